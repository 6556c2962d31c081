#pragma once
// MuJoCo renders ideal pinhole images with square pixels and a centred principal point. A real
// ring camera has fx != fy, an off-centre principal point and strong barrel distortion, so each
// camera is rendered through a wider "render pinhole" and resampled into the calibrated model.
#include "trimbot/robot/camera_rig.h"

namespace trimbot::sim {

struct RenderPinhole {
  int width = 0;
  int height = 0;
  double focal = 0.0;  // px, square pixels
  double cx = 0.0;
  double cy = 0.0;
  double fovy_degrees = 0.0;  // what MuJoCo's camera needs
};

// The smallest centred pinhole that sees every ray of the calibrated camera, sampled with
// `oversampling` times the calibrated focal length.
RenderPinhole RenderPinholeFor(const robot::PinholeRadtan& camera, double oversampling = 1.0);

// Calibrated camera model scaled to another output resolution (e.g. half resolution for speed).
robot::PinholeRadtan Scaled(const robot::PinholeRadtan& camera, double scale);

}  // namespace trimbot::sim
