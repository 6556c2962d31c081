#include "evaluation/pose_errors.h"

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

double AngleDifference(double a, double b) { return std::remainder(a - b, 2.0 * M_PI); }

}  // namespace trimbot::scenarios
