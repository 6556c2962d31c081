#pragma once
// The cameras' automatic exposure (robot::AutoExposure) applied to a rendered image: the renderer
// gives the scene at a fixed daylight exposure; a real sensor meters the ground and adjusts its
// exposure time, then its gain. Plain function of the image: the same image, the same result.
#include <opencv2/core.hpp>

#include "trimbot/robot/robot_parameters.h"

namespace trimbot::sim {

struct ExposureResult {
  double exposure_factor = 1.0;  // relative to the rendered exposure (time)
  double gain = 1.0;             // analogue gain on top (amplifies read noise)
};

// Scales `rgb` (CV_8UC3) in place, saturating at 255; returns what the sensor chose.
ExposureResult ApplyAutoExposure(cv::Mat& rgb, const robot::AutoExposure& parameters);

}  // namespace trimbot::sim
