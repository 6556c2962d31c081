#include "evaluation/pose_errors.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace trimbot::scenarios {

double RotationErrorDegrees(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  const Eigen::Matrix3d delta = estimate.linear().transpose() * truth.linear();
  const double c = std::clamp((delta.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

double TranslationError(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  return (estimate.translation() - truth.translation()).norm();
}

double PlanarNees(const Eigen::Vector3d& error, const Eigen::Matrix3d& covariance) {
  return error.dot(covariance.ldlt().solve(error));
}

double LargestPositionSigma(const Eigen::Matrix3d& covariance) {
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(covariance.topLeftCorner<2, 2>()).eigenvalues()(1));
}

}  // namespace trimbot::scenarios
