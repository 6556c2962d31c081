#include "evaluation/stereo_evaluation.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace trimbot::scenarios {

cv::Mat GroundTruthDisparity(const perception::StereoRectifier& rectifier, const cv::Mat& depth) {
  const cv::Size size = rectifier.image_size();
  if (depth.type() != CV_32FC1 || depth.size() != size) {
    throw std::invalid_argument("GroundTruthDisparity: needs CV_32F depth of " + std::to_string(size.width) + "x" +
                                std::to_string(size.height) + ", got " + std::to_string(depth.cols) + "x" +
                                std::to_string(depth.rows));
  }
  const robot::PinholeRadtan& camera = rectifier.left_camera();
  const Eigen::Matrix3d& R = rectifier.R_rectified_left();
  const double f_times_b = rectifier.focal_length() * rectifier.baseline();
  const float none = std::numeric_limits<float>::quiet_NaN();
  // Rays of the original pixels, each computed once: rectified pixels share original ones.
  cv::Mat ray_x(size, CV_64F, cv::Scalar(std::numeric_limits<double>::quiet_NaN())), ray_y(size, CV_64F);
  cv::Mat disparity(size, CV_32F, cv::Scalar(none));
  for (int v = 0; v < size.height; ++v) {
    const float* map_x = rectifier.left_map_x().ptr<float>(v);
    const float* map_y = rectifier.left_map_y().ptr<float>(v);
    float* out = disparity.ptr<float>(v);
    for (int u = 0; u < size.width; ++u) {
      // Nearest original pixel: depth must not be blended across object edges.
      const int original_u = static_cast<int>(std::lround(map_x[u]));
      const int original_v = static_cast<int>(std::lround(map_y[u]));
      if (original_u < 0 || original_v < 0 || original_u >= size.width || original_v >= size.height) continue;
      const double z = depth.at<float>(original_v, original_u);
      if (!(z > 0.0) || !std::isfinite(z)) continue;
      double& x_over_z = ray_x.at<double>(original_v, original_u);
      double& y_over_z = ray_y.at<double>(original_v, original_u);
      if (std::isnan(x_over_z)) {
        const Eigen::Vector2d ray = camera.Undistort(Eigen::Vector2d(original_u, original_v));
        x_over_z = ray.x();
        y_over_z = ray.y();
      }
      const double z_rectified = (R * Eigen::Vector3d(x_over_z * z, y_over_z * z, z)).z();
      if (z_rectified > 0.0) out[u] = static_cast<float>(f_times_b / z_rectified);
    }
  }
  return disparity;
}

StereoErrors EvaluateDisparity(const cv::Mat& estimate, const cv::Mat& ground_truth, int disparities) {
  if (estimate.type() != CV_32FC1 || ground_truth.type() != CV_32FC1 || estimate.size() != ground_truth.size()) {
    throw std::invalid_argument("EvaluateDisparity: needs two CV_32F disparity images of one size");
  }
  const double max_disparity = disparities - 1;
  StereoErrors errors;
  double sum_abs = 0.0;
  int bad1 = 0, bad2 = 0, estimates = 0, spurious = 0;
  for (int v = 0; v < estimate.rows; ++v) {
    const float* truth_row = ground_truth.ptr<float>(v);
    const float* estimate_row = estimate.ptr<float>(v);
    for (int u = 0; u < estimate.cols; ++u) {
      const double truth = truth_row[u];
      if (!std::isnan(estimate_row[u])) {
        ++estimates;
        spurious += std::isnan(truth) ? 1 : 0;
      }
      // Outside the range, or matched outside the right image: no matcher could find it.
      if (!(truth >= 0.0 && truth <= max_disparity) || u - truth < 0.0) continue;
      ++errors.ground_truth_pixels;
      const double value = estimate_row[u];
      if (std::isnan(value)) continue;
      ++errors.evaluated_pixels;
      const double error = std::abs(value - truth);
      sum_abs += error;
      bad1 += error > 1.0 ? 1 : 0;
      bad2 += error > 2.0 ? 1 : 0;
    }
  }
  if (errors.evaluated_pixels > 0) {
    errors.mean_abs_error = sum_abs / errors.evaluated_pixels;
    errors.bad1_percent = 100.0 * bad1 / errors.evaluated_pixels;
    errors.bad2_percent = 100.0 * bad2 / errors.evaluated_pixels;
  }
  if (estimates > 0) errors.spurious_percent = 100.0 * spurious / estimates;
  if (errors.ground_truth_pixels > 0) {
    errors.completeness_percent = 100.0 * errors.evaluated_pixels / errors.ground_truth_pixels;
  }
  return errors;
}

}  // namespace trimbot::scenarios
