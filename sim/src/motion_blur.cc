#include "trimbot/sim/motion_blur.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace trimbot::sim {

namespace {
constexpr int kMaxSamples = 32;  // along the longest blur (one per pixel of it, up to this)
}

Eigen::Vector2d MotionBlur::Blur(const robot::PinholeRadtan& camera, double x, double y, double depth,
                                 const CameraTwist& twist, double exposure) {
  // A static point P = Z (x, y, 1) seen from a camera moving with (v, w) moves in the camera frame
  // as dP/dt = -v - w x P; its image (x, y) = (P_x / P_z, P_y / P_z) then moves as below. A far
  // point (depth 0) only sees the rotation.
  const Eigen::Vector3d& v = twist.linear;
  const Eigen::Vector3d& w = twist.angular;
  const double inverse_depth = depth > 0.0 ? 1.0 / depth : 0.0;
  const double dx = (-v.x() + x * v.z()) * inverse_depth + x * y * w.x() - (1.0 + x * x) * w.y() + y * w.z();
  const double dy = (-v.y() + y * v.z()) * inverse_depth + (1.0 + y * y) * w.x() - x * y * w.y() - x * w.z();
  return Eigen::Vector2d(camera.fx * dx, camera.fy * dy) * exposure;
}

const cv::Mat& MotionBlur::Rays(int camera_key, const robot::PinholeRadtan& camera) {
  auto found = rays_.find(camera_key);
  if (found != rays_.end() && found->second.cols == camera.width && found->second.rows == camera.height) {
    return found->second;
  }
  cv::Mat rays(camera.height, camera.width, CV_32FC2);
  for (int r = 0; r < camera.height; ++r) {
    for (int c = 0; c < camera.width; ++c) {
      const Eigen::Vector2d ray = camera.Undistort(Eigen::Vector2d(c, r));
      rays.at<cv::Vec2f>(r, c) = cv::Vec2f(static_cast<float>(ray.x()), static_cast<float>(ray.y()));
    }
  }
  return rays_[camera_key] = rays;
}

double MotionBlur::Apply(int camera_key, const robot::PinholeRadtan& camera, const cv::Mat& depth,
                         const CameraTwist& twist, double exposure, cv::Mat* rgb) {
  // A bound first (most daylight frames end here): the corners' rotation, the nearest point's
  // translation.
  double nearest = 0.0;
  if (!depth.empty()) {
    cv::Mat valid = depth > 0.0f;
    if (cv::countNonZero(valid) > 0) cv::minMaxLoc(depth, &nearest, nullptr, nullptr, nullptr, valid);
  }
  // (x 1.25: the lens's barrel distortion puts the corners' rays further out than their pixels.)
  const double corner = 1.25 * std::hypot(std::max(camera.cx, camera.width - camera.cx) / camera.fx,
                                          std::max(camera.cy, camera.height - camera.cy) / camera.fy);
  const double focal = std::max(camera.fx, camera.fy);
  const double bound = exposure * focal *
                       (twist.angular.norm() * (1.0 + corner * corner) +
                        (nearest > 0.0 ? twist.linear.norm() * (1.0 + corner) / nearest : 0.0));
  if (bound < kNegligibleBlurPixels) return bound;
  const cv::Mat& rays = Rays(camera_key, camera);
  cv::Mat blur(rgb->size(), CV_32FC2);
  double longest = 0.0;
  for (int r = 0; r < rgb->rows; ++r) {
    const cv::Vec2f* ray = rays.ptr<cv::Vec2f>(r);
    const float* z = depth.empty() ? nullptr : depth.ptr<float>(r);
    cv::Vec2f* out = blur.ptr<cv::Vec2f>(r);
    for (int c = 0; c < rgb->cols; ++c) {
      const Eigen::Vector2d b = Blur(camera, ray[c][0], ray[c][1], z ? z[c] : 0.0, twist, exposure);
      out[c] = cv::Vec2f(static_cast<float>(b.x()), static_cast<float>(b.y()));
      longest = std::max(longest, b.norm());
    }
  }
  if (longest < kNegligibleBlurPixels) return longest;
  // The shutter integrates uniformly over the exposure: average the image sampled along each
  // pixel's blur, centred on the mid-exposure position (the stamp's).
  const int samples = std::clamp(static_cast<int>(std::ceil(longest)) + 1, 2, kMaxSamples);
  cv::Mat sum(rgb->size(), CV_32FC3, cv::Scalar::all(0.0));
  cv::Mat map_x(rgb->size(), CV_32F), map_y(rgb->size(), CV_32F), sample;
  for (int k = 0; k < samples; ++k) {
    const float s = static_cast<float>(k) / static_cast<float>(samples - 1) - 0.5f;
    for (int r = 0; r < rgb->rows; ++r) {
      const cv::Vec2f* b = blur.ptr<cv::Vec2f>(r);
      float* mx = map_x.ptr<float>(r);
      float* my = map_y.ptr<float>(r);
      for (int c = 0; c < rgb->cols; ++c) {
        mx[c] = static_cast<float>(c) + s * b[c][0];
        my[c] = static_cast<float>(r) + s * b[c][1];
      }
    }
    cv::remap(*rgb, sample, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    cv::accumulate(sample, sum);
  }
  sum.convertTo(*rgb, CV_8UC3, 1.0 / samples);
  return longest;
}

}  // namespace trimbot::sim
