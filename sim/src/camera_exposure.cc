#include "trimbot/sim/camera_exposure.h"

#include <algorithm>
#include <cmath>

namespace trimbot::sim {

ExposureResult MeterExposure(const cv::Mat& rgb, const robot::AutoExposure& parameters) {
  ExposureResult result;
  if (!parameters.enabled || rgb.empty()) return result;
  const int top = static_cast<int>(std::lround(parameters.metering_top * rgb.rows));
  const cv::Scalar mean = cv::mean(rgb.rowRange(std::min(top, rgb.rows - 1), rgb.rows));
  const double metered = std::max(1.0, (mean[0] + mean[1] + mean[2]) / 3.0);
  const double wanted = parameters.target_mean / metered;
  result.exposure_factor = std::clamp(wanted, parameters.min_exposure_factor(), parameters.max_exposure_factor());
  result.gain = std::clamp(wanted / result.exposure_factor, 1.0, parameters.max_gain);
  return result;
}

}  // namespace trimbot::sim
