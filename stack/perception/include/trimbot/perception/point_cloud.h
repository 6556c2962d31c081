#pragma once
// Point clouds with per-point uncertainty: the plain data between stereo, registration and fusion.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace trimbot::perception {

struct PointCloud {
  std::vector<Eigen::Vector3d> points;       // m, in the cloud's frame
  std::vector<Eigen::Matrix3d> covariances;  // m^2, one per point (symmetric positive definite)

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  void Add(const Eigen::Vector3d& point, const Eigen::Matrix3d& covariance) {
    points.push_back(point);
    covariances.push_back(covariance);
  }
};

// Points dropped by CleanCloud, by reason.
struct CleanReport {
  int non_finite = 0;           // NaN, infinite or absurd (> 1e6 m) coordinates, or NaN covariance
  int unusable_covariance = 0;  // not symmetric positive definite, or above max_variance
  int kept = 0;
};

// The cloud without points whose coordinates or covariance are unusable (non-finite, not
// symmetric positive definite, or a covariance above `max_variance` m^2 on any axis, which some data
// sets use to mark invalid points). Counts what was dropped. Throws std::invalid_argument when the
// points and covariances differ in number.
PointCloud CleanCloud(const PointCloud& cloud, double max_variance, CleanReport* report = nullptr);

}  // namespace trimbot::perception
