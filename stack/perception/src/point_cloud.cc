#include "trimbot/perception/point_cloud.h"

#include <Eigen/Cholesky>
#include <stdexcept>

namespace trimbot::perception {

// Beyond this (m) a coordinate is garbage, not a garden; it would also overflow voxel indices.
constexpr double kMaxCoordinate = 1e6;

PointCloud CleanCloud(const PointCloud& cloud, double max_variance, CleanReport* report) {
  if (cloud.points.size() != cloud.covariances.size()) {
    throw std::invalid_argument("point cloud has " + std::to_string(cloud.points.size()) + " points but " +
                                std::to_string(cloud.covariances.size()) + " covariances");
  }
  CleanReport counts;
  PointCloud out;
  out.points.reserve(cloud.size());
  out.covariances.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.points[i];
    const Eigen::Matrix3d& c = cloud.covariances[i];
    if (!p.allFinite() || !c.allFinite() || p.cwiseAbs().maxCoeff() > kMaxCoordinate) {
      ++counts.non_finite;
      continue;
    }
    const bool symmetric = (c - c.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * std::max(1.0, c.cwiseAbs().maxCoeff());
    if (!symmetric || c.llt().info() != Eigen::Success || c.diagonal().maxCoeff() > max_variance) {
      ++counts.unusable_covariance;
      continue;
    }
    out.Add(p, c);
  }
  counts.kept = static_cast<int>(out.size());
  if (report != nullptr) *report = counts;
  return out;
}

}  // namespace trimbot::perception
