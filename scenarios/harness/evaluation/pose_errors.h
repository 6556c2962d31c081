#pragma once
// Errors of an estimated pose against the ground truth.
#include <Eigen/Geometry>

namespace trimbot::scenarios {

// Geodesic rotation error in degrees and translation error in metres of `estimate` against `truth`.
double RotationErrorDegrees(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);
double TranslationError(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);
// Planar heading difference a - b wrapped to [-pi, pi].
double AngleDifference(double a, double b);

}  // namespace trimbot::scenarios
