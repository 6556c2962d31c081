#include "map_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

#include "trimbot/common/rotation.h"

namespace trimbot::visual_localization::mapping {
namespace {

using Pose6 = std::array<double, 6>;  // angle-axis of R_map_base, then base_link's position in the map

Pose6 ToPose6(const Eigen::Isometry3d& T) {
  const Eigen::AngleAxisd aa(T.linear());
  const Eigen::Vector3d w = aa.angle() * aa.axis(), t = T.translation();
  return {w.x(), w.y(), w.z(), t.x(), t.y(), t.z()};
}

Eigen::Isometry3d FromPose6(const Pose6& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotationFromVector(Eigen::Vector3d(p[0], p[1], p[2]));
  T.translation() << p[3], p[4], p[5];
  return T;
}

std::vector<Pose6> ToPoses(const std::vector<MappingKeyframe>& keyframes) {
  std::vector<Pose6> poses;
  for (const auto& k : keyframes) poses.push_back(ToPose6(k.T_map_base));
  return poses;
}

void FromPoses(const std::vector<Pose6>& poses, std::vector<MappingKeyframe>& keyframes) {
  for (std::size_t k = 0; k < keyframes.size(); ++k) keyframes[k].T_map_base = FromPose6(poses[k]);
}

// The angle-axis of R_a^T R_b (both as angle-axis), for rotation residuals.
template <typename T>
void RelativeRotation(const Eigen::Matrix3d& R_a_transposed, const T* const b, T* angle_axis) {
  T R[9];
  ceres::AngleAxisToRotationMatrix(b, R);  // column-major
  const Eigen::Matrix<T, 3, 3> delta = R_a_transposed.cast<T>() * Eigen::Map<const Eigen::Matrix<T, 3, 3>>(R);
  T delta_cm[9];
  Eigen::Map<Eigen::Matrix<T, 3, 3>> delta_map(delta_cm);
  delta_map = delta;
  ceres::RotationMatrixToAngleAxis(delta_cm, angle_axis);
}

// Observed normalized image point vs the projection of a map point, in pixels / sigma.
struct ReprojectionError {
  Eigen::Vector2d observed;  // normalized (x/z, y/z) in the camera
  Eigen::Matrix3d R_cam_base;
  Eigen::Vector3d t_cam_base;
  double scale;  // focal length / pixel sigma

  template <typename T>
  bool operator()(const T* const pose, const T* const point, T* residual) const {
    T p[3] = {point[0] - pose[3], point[1] - pose[4], point[2] - pose[5]};
    T inverse[3] = {-pose[0], -pose[1], -pose[2]};
    T in_base[3];
    ceres::AngleAxisRotatePoint(inverse, p, in_base);
    Eigen::Matrix<T, 3, 1> in_camera =
        R_cam_base.cast<T>() * Eigen::Matrix<T, 3, 1>(in_base[0], in_base[1], in_base[2]) + t_cam_base.cast<T>();
    if (in_camera(2) < T(1e-3)) in_camera(2) = T(1e-3);
    residual[0] = T(scale) * (in_camera(0) / in_camera(2) - T(observed.x()));
    residual[1] = T(scale) * (in_camera(1) / in_camera(2) - T(observed.y()));
    return true;
  }
};

// The survey's pose of a keyframe as a soft constraint.
struct PosePrior {
  Eigen::Matrix3d R_prior_transposed;
  Eigen::Vector3d t_prior;
  double rotation_sigma, position_sigma;

  template <typename T>
  bool operator()(const T* const pose, T* residual) const {
    T angle_axis[3];
    RelativeRotation(R_prior_transposed, pose, angle_axis);
    for (int i = 0; i < 3; ++i) {
      residual[i] = angle_axis[i] / T(rotation_sigma);
      residual[3 + i] = (pose[3 + i] - T(t_prior(i))) / T(position_sigma);
    }
    return true;
  }
};

// A measured relative pose of keyframe j in keyframe i's frame (odometry, or a loop closure):
// the translation, times the wheels' scale, and the rotation, each axis with its sigma (in i).
struct RelativePoseError {
  Eigen::Matrix3d R_measured;  // R_i^T R_j
  Eigen::Vector3d t_measured;  // R_i^T (t_j - t_i), in wheel distance for odometry
  Eigen::Vector3d translation_sigma, rotation_sigma;

  template <typename T>
  bool operator()(const T* const pose_i, const T* const pose_j, const T* const scale, T* residual) const {
    const T d[3] = {pose_j[3] - pose_i[3], pose_j[4] - pose_i[4], pose_j[5] - pose_i[5]};
    const T inverse_i[3] = {-pose_i[0], -pose_i[1], -pose_i[2]};
    T d_in_i[3];
    ceres::AngleAxisRotatePoint(inverse_i, d, d_in_i);
    // The rotation left over: (R_i R_measured)^T R_j.
    T R_i[9], R_j[9];
    ceres::AngleAxisToRotationMatrix(pose_i, R_i);  // column-major
    ceres::AngleAxisToRotationMatrix(pose_j, R_j);
    const Eigen::Matrix<T, 3, 3> R_expected = Eigen::Map<const Eigen::Matrix<T, 3, 3>>(R_i) * R_measured.cast<T>();
    T left_over[9];
    Eigen::Map<Eigen::Matrix<T, 3, 3>> left_over_map(left_over);
    left_over_map = R_expected.transpose() * Eigen::Map<const Eigen::Matrix<T, 3, 3>>(R_j);
    T angle_axis[3];
    ceres::RotationMatrixToAngleAxis(left_over, angle_axis);
    for (int a = 0; a < 3; ++a) {
      residual[a] = (d_in_i[a] - scale[0] * T(t_measured(a))) / T(translation_sigma(a));
      residual[3 + a] = angle_axis[a] / T(rotation_sigma(a));
    }
    return true;
  }
};

ceres::CostFunction* MakeRelativePoseCost(const Eigen::Isometry3d& T_i_j, const Eigen::Vector3d& translation_sigma,
                                          const Eigen::Vector3d& rotation_sigma) {
  return new ceres::AutoDiffCostFunction<RelativePoseError, 6, 6, 6, 1>(
      new RelativePoseError{T_i_j.linear(), T_i_j.translation(), translation_sigma, rotation_sigma});
}

// The odometry's sigmas for a step: along track and sideways grow with the distance, yaw with the turn.
void OdometrySigmas(const Eigen::Isometry3d& T_i_j, const OdometryFactorOptions& o, Eigen::Vector3d* translation,
                    Eigen::Vector3d* rotation) {
  const double d = T_i_j.translation().head<2>().norm();
  const double turn = std::abs(Eigen::AngleAxisd(T_i_j.linear()).angle());
  *translation = {o.along_sigma + o.along_sigma_per_m * d, o.lateral_sigma + o.lateral_sigma_per_m * d, o.height_sigma};
  *rotation = {o.tilt_sigma, o.tilt_sigma, o.yaw_sigma + o.yaw_sigma_per_rad * turn};
}

struct ScalePrior {
  double sigma;
  template <typename T>
  bool operator()(const T* const s, T* residual) const {
    residual[0] = (s[0] - T(1.0)) / T(sigma);
    return true;
  }
};

struct ScaleChange {
  double sigma;
  template <typename T>
  bool operator()(const T* const a, const T* const b, T* residual) const {
    residual[0] = (b[0] - a[0]) / T(sigma);
    return true;
  }
};

// Odometry factors between consecutive keyframes (their prior poses are the odometry's), with
// the wheel scales and their priors; keyframe 0 fixed (the gauge: the believed start).
void AddOdometryFactors(const OdometryFactorOptions& o, const std::vector<MappingKeyframe>& keyframes,
                        std::vector<Pose6>& poses, WheelScales& scales, ceres::Problem* problem) {
  for (std::size_t k = 1; k < keyframes.size(); ++k) {
    const Eigen::Isometry3d T_i_j = keyframes[k - 1].T_prior.inverse() * keyframes[k].T_prior;
    Eigen::Vector3d translation_sigma, rotation_sigma;
    OdometrySigmas(T_i_j, o, &translation_sigma, &rotation_sigma);
    problem->AddResidualBlock(MakeRelativePoseCost(T_i_j, translation_sigma, rotation_sigma), nullptr,
                              poses[k - 1].data(), poses[k].data(), &scales.scale[scales.stretch_of_step[k]]);
  }
  for (std::size_t s = 0; s < scales.scale.size(); ++s) {
    if (!problem->HasParameterBlock(&scales.scale[s])) continue;
    if (s == 0) {
      problem->AddResidualBlock(new ceres::AutoDiffCostFunction<ScalePrior, 1, 1>(new ScalePrior{o.scale_prior_sigma}),
                                nullptr, &scales.scale[0]);
    } else if (problem->HasParameterBlock(&scales.scale[s - 1])) {
      problem->AddResidualBlock(
          new ceres::AutoDiffCostFunction<ScaleChange, 1, 1, 1>(new ScaleChange{o.scale_change_sigma}), nullptr,
          &scales.scale[s - 1], &scales.scale[s]);
    }
  }
  if (!poses.empty() && problem->HasParameterBlock(poses[0].data()))
    problem->SetParameterBlockConstant(poses[0].data());
}

ceres::Solver::Options SolverOptions(int iterations) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_SCHUR;
  solver.max_num_iterations = iterations;
  solver.num_threads = 1;  // one thread: the same map, bit for bit, from the same drive
  return solver;
}

}  // namespace

WheelScales MakeWheelScales(const std::vector<MappingKeyframe>& keyframes, const OdometryFactorOptions& options) {
  WheelScales scales;
  scales.stretch_of_step.assign(keyframes.size(), 0);
  double travelled = 0.0;
  for (std::size_t k = 1; k < keyframes.size(); ++k) {
    const double step = (keyframes[k].T_prior.translation() - keyframes[k - 1].T_prior.translation()).norm();
    scales.stretch_of_step[k] = static_cast<int>(std::floor(travelled / options.scale_stretch));
    travelled += step;
  }
  // Numbered consecutively: a step longer than a stretch (frames missing) must not leave a scale no
  // step uses, which would cut the chain of priors between its neighbours.
  std::vector<int> compact(scales.stretch_of_step.size(), 0);
  for (std::size_t k = 2; k < keyframes.size(); ++k) {
    compact[k] = compact[k - 1] + (scales.stretch_of_step[k] != scales.stretch_of_step[k - 1] ? 1 : 0);
  }
  scales.stretch_of_step = compact;
  scales.scale.assign(static_cast<std::size_t>(compact.empty() ? 1 : compact.back() + 1), 1.0);
  return scales;
}

double Adjust(const robot::CameraRig& rig, const MapBuilderOptions& options, std::vector<MappingKeyframe>& keyframes,
              std::vector<PointTrack>& points, WheelScales& scales, std::vector<double>* errors) {
  std::vector<Pose6> poses = ToPoses(keyframes);
  ceres::Problem problem;
  std::vector<ceres::ResidualBlockId> blocks;
  for (auto& p : points) {
    for (const auto& r : p.track) {
      const robot::CameraCalibration& camera = rig.camera(r.camera);
      const Eigen::Isometry3d T_cam_base = camera.T_base_camera.inverse();
      const Eigen::Vector3d& bearing = keyframes[r.keyframe].images[r.camera].bearings[r.feature];
      const double scale = camera.intrinsics.fx / options.pixel_sigma;
      auto* cost = new ceres::AutoDiffCostFunction<ReprojectionError, 2, 6, 3>(
          new ReprojectionError{bearing.head<2>() / bearing.z(), T_cam_base.linear(), T_cam_base.translation(), scale});
      blocks.push_back(
          problem.AddResidualBlock(cost, new ceres::HuberLoss(2.0), poses[r.keyframe].data(), p.position.data()));
    }
  }
  if (options.poses == KeyframePoses::kSurveyed) {
    for (std::size_t k = 0; k < keyframes.size(); ++k) {
      auto* prior = new ceres::AutoDiffCostFunction<PosePrior, 6, 6>(
          new PosePrior{keyframes[k].T_prior.linear().transpose(), keyframes[k].T_prior.translation(),
                        options.survey_rotation_sigma, options.survey_position_sigma});
      problem.AddResidualBlock(prior, nullptr, poses[k].data());
    }
  } else {
    AddOdometryFactors(options.odometry, keyframes, poses, scales, &problem);
  }
  ceres::Solver::Summary summary;
  if (!blocks.empty()) ceres::Solve(SolverOptions(options.adjustment_iterations), &problem, &summary);
  FromPoses(poses, keyframes);
  // RMS of the pixel residuals (the cost functions are scaled by 1/sigma).
  double sum = 0.0;
  errors->clear();
  for (const auto id : blocks) {
    double residual[2];
    problem.EvaluateResidualBlock(id, false, nullptr, residual, nullptr);
    const double squared =
        (residual[0] * residual[0] + residual[1] * residual[1]) * options.pixel_sigma * options.pixel_sigma;
    sum += squared;
    errors->push_back(std::sqrt(squared));
  }
  return blocks.empty() ? 0.0 : std::sqrt(sum / (2.0 * blocks.size()));
}

void OptimizePoseGraph(const MapBuilderOptions& options, std::vector<MappingKeyframe>& keyframes,
                       std::vector<LoopEdge>& loops) {
  std::vector<Pose6> poses = ToPoses(keyframes);
  double unit_scale = 1.0;
  ceres::Problem problem;
  for (std::size_t k = 1; k < keyframes.size(); ++k) {
    const Eigen::Isometry3d T_i_j = keyframes[k - 1].T_map_base.inverse() * keyframes[k].T_map_base;
    Eigen::Vector3d translation_sigma, rotation_sigma;
    OdometrySigmas(T_i_j, options.odometry, &translation_sigma, &rotation_sigma);
    problem.AddResidualBlock(MakeRelativePoseCost(T_i_j, translation_sigma, rotation_sigma), nullptr,
                             poses[k - 1].data(), poses[k].data(), &unit_scale);
  }
  const LoopClosureOptions& l = options.loops;
  std::vector<ceres::ResidualBlockId> loop_blocks;
  for (const auto& loop : loops) {
    loop_blocks.push_back(problem.AddResidualBlock(
        MakeRelativePoseCost(loop.T_match_query, Eigen::Vector3d::Constant(l.position_sigma),
                             Eigen::Vector3d::Constant(l.rotation_sigma)),
        new ceres::CauchyLoss(l.loss_scale), poses[loop.match].data(), poses[loop.query].data(), &unit_scale));
  }
  if (loops.empty() || keyframes.size() < 2) return;
  problem.SetParameterBlockConstant(poses[0].data());
  problem.SetParameterBlockConstant(&unit_scale);
  ceres::Solver::Options solver = SolverOptions(100);
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  FromPoses(poses, keyframes);
  // Cauchy's weight rho'(s) = 1 / (1 + s / a^2) at each loop's squared residual s.
  for (std::size_t i = 0; i < loops.size(); ++i) {
    std::array<double, 6> residual{};
    problem.EvaluateResidualBlock(loop_blocks[i], false, nullptr, residual.data(), nullptr);
    double s = 0.0;
    for (double r : residual) s += r * r;
    loops[i].weight = 1.0 / (1.0 + s / (l.loss_scale * l.loss_scale));
  }
}

namespace {

// The signed distance to the union of the shapes: the smallest (continuous where shapes overlap,
// unlike the distance of the nearest surface, whose jumps would swamp the Jacobian).
double UnionSignedDistance(const std::vector<SurveyedShape>& shapes, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& shape : shapes) best = std::min(best, shape.SignedDistance(p));
  return best;
}

Eigen::Vector3d Apply(const Eigen::Vector3d& tie, const Eigen::Vector3d& p) {
  const double c = std::cos(tie.z()), s = std::sin(tie.z());
  return {c * p.x() - s * p.y() + tie.x(), s * p.x() + c * p.y() + tie.y(), p.z()};
}

}  // namespace

Eigen::Vector3d TieToShapes(const std::vector<PointTrack>& points, const std::vector<SurveyedShape>& shapes,
                            const TieOptions& options, int* used, double* median) {
  *used = 0;
  *median = 0.0;
  std::vector<Eigen::Vector3d> above;
  for (const auto& p : points) {
    if (p.position.z() >= options.min_height) above.push_back(p.position);
  }
  Eigen::Vector3d tie = Eigen::Vector3d::Zero();  // x, y, yaw
  if (above.empty() || shapes.empty()) return tie;
  constexpr double kStep = 1e-4;  // m (and rad): finite differences of the distance
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    const double f = options.iterations > 1 ? static_cast<double>(iteration) / (options.iterations - 1) : 1.0;
    const double gate = options.start_distance + f * (options.end_distance - options.start_distance);
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    std::vector<double> distances;
    for (const auto& p : above) {
      const double r = UnionSignedDistance(shapes, Apply(tie, p));
      if (std::abs(r) > gate) continue;
      Eigen::Vector3d J;
      for (int a = 0; a < 3; ++a) {
        Eigen::Vector3d moved = tie;
        moved(a) += kStep;
        J(a) = (UnionSignedDistance(shapes, Apply(moved, p)) - r) / kStep;
      }
      const double w = std::abs(r) <= options.huber ? 1.0 : options.huber / std::abs(r);
      H += w * J * J.transpose();
      g += w * J * r;
      distances.push_back(std::abs(r));
    }
    *used = static_cast<int>(distances.size());
    if (!distances.empty()) {
      std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
      *median = distances[distances.size() / 2];
    }
    if (distances.size() < 3) break;
    const Eigen::Vector3d step = -(H + 1e-9 * Eigen::Matrix3d::Identity()).ldlt().solve(g);
    tie += step;
  }
  return tie;
}

}  // namespace trimbot::visual_localization::mapping
