#include "evaluation/map_evaluation.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <stdexcept>

#include "evaluation/pose_errors.h"
#include "evaluation/trial_result.h"
#include "trimbot/common/points_kd_tree.h"

namespace trimbot::scenarios {

nlohmann::json TrajectoryErrors(const std::vector<StampedPose>& estimate, const std::vector<StampedPose>& truth) {
  if (estimate.size() != truth.size()) throw std::logic_error("TrajectoryErrors: trajectories of different lengths");
  const std::size_t n = estimate.size();
  std::vector<double> unaligned, aligned, rpe_translation, rpe_rotation;
  Eigen::Matrix3Xd from(3, static_cast<Eigen::Index>(n)), to(3, static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) {
    from.col(static_cast<Eigen::Index>(i)) = estimate[i].T.translation();
    to.col(static_cast<Eigen::Index>(i)) = truth[i].T.translation();
    unaligned.push_back(TranslationError(estimate[i].T, truth[i].T));
    if (i == 0) continue;
    const Eigen::Isometry3d step_estimate = estimate[i - 1].T.inverse() * estimate[i].T;
    const Eigen::Isometry3d step_truth = truth[i - 1].T.inverse() * truth[i].T;
    rpe_translation.push_back(TranslationError(step_estimate, step_truth));
    rpe_rotation.push_back(RotationErrorDegrees(step_estimate, step_truth));
  }
  Eigen::Isometry3d alignment = Eigen::Isometry3d::Identity();
  if (n >= 3) alignment.matrix() = Eigen::umeyama(from, to, false);
  for (std::size_t i = 0; i < n; ++i) aligned.push_back(TranslationError(alignment * estimate[i].T, truth[i].T));
  const Eigen::AngleAxisd rotation(alignment.linear());
  return {{"ate_unaligned_m", nlohmann::json(ErrorStats::From(unaligned))},
          {"ate_se3_aligned_m", nlohmann::json(ErrorStats::From(aligned))},
          {"alignment",
           {{"translation_m", alignment.translation().norm()}, {"rotation_deg", rotation.angle() * 180 / M_PI}}},
          {"rpe_per_keyframe_m", nlohmann::json(ErrorStats::From(rpe_translation))},
          {"rpe_per_keyframe_deg", nlohmann::json(ErrorStats::From(rpe_rotation))}};
}

nlohmann::json PointErrors(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& surface) {
  if (points.empty() || surface.empty()) return {{"count", 0}};
  const PointsAdaptor adaptor{surface};
  PointsKdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  tree.buildIndex();
  std::vector<double> distances;
  int within = 0;
  for (const auto& p : points) {
    std::uint32_t index = 0;
    double squared = 0.0;
    nanoflann::KNNResultSet<double, std::uint32_t> result(1);
    result.init(&index, &squared);
    tree.findNeighbors(result, p.data(), nanoflann::SearchParams());
    distances.push_back(std::sqrt(squared));
    within += distances.back() <= 0.05 ? 1 : 0;
  }
  const ErrorStats stats = ErrorStats::From(distances);
  std::sort(distances.begin(), distances.end());
  return {{"count", stats.count},
          {"mean", stats.mean},
          {"median", stats.median},
          {"p90", distances[distances.size() * 9 / 10]},
          {"within_5cm", static_cast<double>(within) / static_cast<double>(points.size())}};
}

}  // namespace trimbot::scenarios
