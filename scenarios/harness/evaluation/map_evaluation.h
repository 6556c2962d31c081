#pragma once
// How good a built map is, against the ground truth (the evaluator's side only; the builder never
// sees any of it): the keyframe trajectory's absolute error unaligned (what the tie to the garden
// left: the error the trials see), after a rigid SE(3) alignment (Umeyama, no scale: the map's
// shape), and the relative error per keyframe step; the same for the odometry the build started
// from; and the map points' distance to the true surfaces.
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <vector>

#include "evaluation/tum_trajectory.h"

namespace trimbot::scenarios {

// Keyframe errors of `estimate` against `truth` (same order, same stamps): ATE unaligned and
// SE(3)-aligned (position, m), RPE per step (m, deg). JSON with count, mean, median, rmse, max.
nlohmann::json TrajectoryErrors(const std::vector<StampedPose>& estimate, const std::vector<StampedPose>& truth);

// Distance (m) of each map point to the nearest surface sample: count, mean, median, p90, and the
// fraction within 5 cm. `surface` should be sampled densely (~1 cm).
nlohmann::json PointErrors(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& surface);

}  // namespace trimbot::scenarios
