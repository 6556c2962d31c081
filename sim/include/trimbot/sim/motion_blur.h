#pragma once
// Motion blur of a global-shutter camera: while the shutter is open the rig moves, and each pixel
// integrates the scene along the path its point takes across the image. For a static scene this
// equals averaging sub-frame renders over the exposure (occlusion edges aside), at the cost of
// resampling instead of rendering: each pixel's image motion follows from the camera's twist and
// the rendered depth (the standard image-motion equations of a pinhole; the lens's distortion
// changes the motion by a few percent at the corners and is left out).
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <map>
#include <utility>

#include "trimbot/robot/camera_rig.h"

namespace trimbot::sim {

// The camera's velocity in its own optical frame (x right, y down, z forward).
struct CameraTwist {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();   // m/s
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();  // rad/s
};

// Below this length (px) a blur is left out: it is under the read noise and the render's own
// anti-aliasing.
constexpr double kNegligibleBlurPixels = 0.05;

class MotionBlur {
 public:
  // Blurs `rgb` (CV_8UC3, the calibrated image of `camera`) by the motion `twist` over `exposure`
  // seconds; `depth` (CV_32F, metres along the optical axis, 0 = far) is the same view's. Returns
  // the longest blur in the image, px (or a bound of it below kNegligibleBlurPixels, left out). `camera_key` names the
  // camera and resolution (its rays are computed once).
  double Apply(int camera_key, const robot::PinholeRadtan& camera, const cv::Mat& depth, const CameraTwist& twist,
               double exposure, cv::Mat* rgb);

  // The blur (px, over the exposure) at normalized image point (x, y) at `depth` m (0: far).
  static Eigen::Vector2d Blur(const robot::PinholeRadtan& camera, double x, double y, double depth,
                              const CameraTwist& twist, double exposure);

 private:
  const cv::Mat& Rays(int camera_key, const robot::PinholeRadtan& camera);
  std::map<int, cv::Mat> rays_;  // CV_32FC2: undistorted normalized coordinates per pixel
};

}  // namespace trimbot::sim
