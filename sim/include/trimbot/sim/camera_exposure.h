#pragma once
// The cameras' automatic exposure (robot::AutoExposure) for a rendered image: the renderer
// gives the scene at a fixed daylight exposure; a real sensor meters the ground and adjusts its
// exposure time, then its gain. Plain function of the image: the same image, the same result.
#include <opencv2/core.hpp>

#include "trimbot/robot/robot_parameters.h"

namespace trimbot::sim {

struct ExposureResult {
  double exposure_factor = 1.0;  // relative to the rendered exposure (time)
  double gain = 1.0;             // analogue gain on top (amplifies read noise)
};

// What the sensor chooses for this rendered image (CV_8UC3); the image is scaled by
// exposure_factor * gain when it is read out (ReadNoise::ReadOut).
ExposureResult MeterExposure(const cv::Mat& rgb, const robot::AutoExposure& parameters);

}  // namespace trimbot::sim
