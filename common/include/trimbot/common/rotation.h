#pragma once
// The rotation of a rotation vector (SO(3) exponential): angle |w| about w / |w|; below 1e-12 rad
// its first-order form, so tiny steps of an optimizer are not rounded to nothing.
#include <Eigen/Geometry>

namespace trimbot {

inline Eigen::Matrix3d RotationFromVector(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-12) {
    Eigen::Matrix3d skew;
    skew << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
    return Eigen::Matrix3d::Identity() + skew;
  }
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

}  // namespace trimbot
