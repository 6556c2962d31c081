#include "open3d_icp.h"

#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/GeneralizedICP.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace trimbot::perception {
namespace {

namespace reg = open3d::pipelines::registration;

open3d::geometry::PointCloud ToOpen3d(const PointCloud& cloud) {
  open3d::geometry::PointCloud out;
  out.points_ = cloud.points;
  return out;
}

}  // namespace

RegistrationResult Open3dIcp(const PointCloud& target, const PointCloud& source, const Eigen::Isometry3d& initial,
                             const RegistrationOptions& options, double start_distance, double point_spacing) {
  open3d::geometry::PointCloud x = ToOpen3d(target), y = ToOpen3d(source);
  if (options.method == RegistrationMethod::kIcpPointToPlane) {
    // Normals from ~30 neighbours within 5 point spacings. (Generalized ICP estimates its own
    // covariances from 20 nearest neighbours: given these normals instead it ended 26 deg off.)
    const open3d::geometry::KDTreeSearchParamHybrid search(5.0 * point_spacing, 30);
    x.EstimateNormals(search);
    y.EstimateNormals(search);
  }
  std::unique_ptr<reg::TransformationEstimation> estimation;
  switch (options.method) {
    case RegistrationMethod::kIcpPointToPlane:
      estimation = std::make_unique<reg::TransformationEstimationPointToPlane>();
      break;
    case RegistrationMethod::kGeneralizedIcp:
      estimation = std::make_unique<reg::TransformationEstimationForGeneralizedICP>();
      break;
    default:
      estimation = std::make_unique<reg::TransformationEstimationPointToPoint>();
  }
  // Coarse to fine: the distance within which points correspond halves per stage down to 3 point
  // spacings.
  std::vector<double> distances;
  const double finest = 3.0 * point_spacing;
  for (double d = start_distance; d > finest; d *= 0.5) distances.push_back(d);
  distances.push_back(finest);
  const int per_stage = std::max(10, options.max_iterations / static_cast<int>(distances.size()));

  RegistrationResult result;
  Eigen::Matrix4d T = initial.matrix();
  reg::RegistrationResult stage;
  for (double distance : distances) {
    // Relative changes of 1e-9: Open3D's generalized ICP takes small steps, and stopped 17 deg
    // short at the default 1e-6.
    const reg::ICPConvergenceCriteria criteria(1e-9, 1e-9, per_stage);
    stage = options.method == RegistrationMethod::kGeneralizedIcp
                ? reg::RegistrationGeneralizedICP(y, x, distance, T, reg::TransformationEstimationForGeneralizedICP(),
                                                  criteria)
                : reg::RegistrationICP(y, x, distance, T, *estimation, criteria);
    if (stage.correspondence_set_.empty()) break;  // nothing within reach: keep the last transform
    T = stage.transformation_;
    result.iterations += per_stage;  // the budget: Open3D does not report how many it used
  }
  result.transform.matrix() = T;
  result.pairs = static_cast<int>(stage.correspondence_set_.size());
  result.final_cost = stage.inlier_rmse_ * stage.inlier_rmse_;
  result.converged = !stage.correspondence_set_.empty();
  return result;
}

}  // namespace trimbot::perception
