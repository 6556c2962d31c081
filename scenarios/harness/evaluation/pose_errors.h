#pragma once
// Errors of an estimated pose against the ground truth.
#include <Eigen/Geometry>

namespace trimbot::scenarios {

// Geodesic rotation error in degrees and translation error in metres of `estimate` against `truth`.
double RotationErrorDegrees(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);
double TranslationError(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);
// Normalized estimation error squared of a planar error (x, y, yaw) against the covariance the
// estimate stated: 3 on average when the covariance is what the error is (not finite for a
// singular covariance).
double PlanarNees(const Eigen::Vector3d& error, const Eigen::Matrix3d& covariance);
// The position sigma a planar covariance states along its worst axis (m).
double LargestPositionSigma(const Eigen::Matrix3d& covariance);

}  // namespace trimbot::scenarios
