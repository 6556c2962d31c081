#include "trimbot/visual_localization/rig_pose.h"

#include <opengv/absolute_pose/NoncentralAbsoluteAdapter.hpp>
#include <opengv/absolute_pose/methods.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/absolute_pose/AbsolutePoseSacProblem.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

#include "trimbot/common/rotation.h"

namespace trimbot::visual_localization {
namespace {

using Problem = opengv::sac_problems::absolute_pose::AbsolutePoseSacProblem;

// Angular residual components of one correspondence for T_map_base (the bearing's deviation from
// the ray to the point, as the two components orthogonal to the bearing).
Eigen::Vector2d Residual(const Correspondence& c, const Eigen::Isometry3d& T_base_camera, const Eigen::Isometry3d& T) {
  const Eigen::Vector3d ray = ((T * T_base_camera).inverse() * c.point).normalized();
  const Eigen::Vector3d e1 = c.bearing.unitOrthogonal(), e2 = c.bearing.cross(e1);
  return {e1.dot(ray), e2.dot(ray)};
}

// Covariance of the pose from the inliers' residuals (Gauss-Newton information, numeric Jacobian).
Eigen::Matrix<double, 6, 6> Covariance(const std::vector<Correspondence>& correspondences,
                                       const std::vector<int>& inliers,
                                       const std::vector<Eigen::Isometry3d>& T_base_camera, const Eigen::Isometry3d& T,
                                       double sigma) {
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  constexpr double h = 1e-6;
  for (int index : inliers) {
    const Correspondence& c = correspondences[static_cast<std::size_t>(index)];
    const Eigen::Isometry3d& Tc = T_base_camera[static_cast<std::size_t>(c.camera)];
    const Eigen::Vector2d r0 = Residual(c, Tc, T);
    Eigen::Matrix<double, 2, 6> J;
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix<double, 6, 1> delta = Eigen::Matrix<double, 6, 1>::Zero();
      delta(k) = h;
      Eigen::Isometry3d perturbed = T;
      perturbed.linear() = RotationFromVector(delta.head<3>()) * T.linear();
      perturbed.translation() += delta.tail<3>();
      J.col(k) = (Residual(c, Tc, perturbed) - r0) / h;
    }
    information += J.transpose() * J / (sigma * sigma);
  }
  return (information + 1e-12 * Eigen::Matrix<double, 6, 6>::Identity()).inverse();
}

}  // namespace

RigPoseResult EstimateRigPose(const std::vector<Correspondence>& correspondences,
                              const std::vector<Eigen::Isometry3d>& T_base_camera, const RigPoseOptions& options) {
  RigPoseResult result;
  if (static_cast<int>(correspondences.size()) < std::max(options.min_inliers, 3)) {
    result.failure = "too few correspondences (" + std::to_string(correspondences.size()) + ")";
    return result;
  }
  opengv::bearingVectors_t bearings;
  opengv::points_t points;
  std::vector<int> cameras;
  for (const auto& c : correspondences) {
    bearings.push_back(c.bearing.normalized());
    points.push_back(c.point);
    cameras.push_back(c.camera);
  }
  opengv::translations_t offsets;
  opengv::rotations_t rotations;
  for (const auto& T : T_base_camera) {
    offsets.push_back(T.translation());
    rotations.push_back(T.linear());
  }
  opengv::absolute_pose::NoncentralAbsoluteAdapter adapter(bearings, cameras, points, offsets, rotations);
  opengv::sac::Ransac<Problem> ransac;
  ransac.sac_model_ = std::make_shared<Problem>(adapter, Problem::GP3P, /*randomSeed=*/false);
  ransac.threshold_ = 1.0 - std::cos(options.inlier_angle);
  ransac.max_iterations_ = options.max_iterations;
  if (!ransac.computeModel() || static_cast<int>(ransac.inliers_.size()) < options.min_inliers) {
    result.failure = "RANSAC found " + std::to_string(ransac.inliers_.size()) + " inliers, " +
                     std::to_string(options.min_inliers) + " needed";
    return result;
  }
  // Refine on the inliers from the RANSAC model (transformation of base_link in the map).
  adapter.sett(ransac.model_coefficients_.col(3));
  adapter.setR(ransac.model_coefficients_.block<3, 3>(0, 0));
  const opengv::transformation_t refined = opengv::absolute_pose::optimize_nonlinear(adapter, ransac.inliers_);
  result.T_map_base.linear() = refined.block<3, 3>(0, 0);
  result.T_map_base.translation() = refined.col(3);
  // The inliers of the refined pose.
  for (std::size_t i = 0; i < correspondences.size(); ++i) {
    const Correspondence& c = correspondences[i];
    const Eigen::Vector3d ray =
        ((result.T_map_base * T_base_camera[static_cast<std::size_t>(c.camera)]).inverse() * c.point).normalized();
    if (std::acos(std::clamp(ray.dot(c.bearing.normalized()), -1.0, 1.0)) <= options.inlier_angle) {
      result.inliers.push_back(static_cast<int>(i));
    }
  }
  if (static_cast<int>(result.inliers.size()) < options.min_inliers) {
    result.failure = "refinement left " + std::to_string(result.inliers.size()) + " inliers";
    return result;
  }
  if (static_cast<double>(result.inliers.size()) <
      options.min_inlier_ratio * static_cast<double>(correspondences.size())) {
    result.failure = std::to_string(result.inliers.size()) + " inliers of " + std::to_string(correspondences.size()) +
                     " correspondences, under the minimum ratio " + std::to_string(options.min_inlier_ratio);
    return result;
  }
  result.covariance =
      Covariance(correspondences, result.inliers, T_base_camera, result.T_map_base, options.angle_sigma);
  result.success = true;
  return result;
}

}  // namespace trimbot::visual_localization
