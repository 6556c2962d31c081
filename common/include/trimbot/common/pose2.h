#pragma once
// The one planar pose of the project: x, y and heading of a frame (e.g. base_link) in the frame it
// is given in (map or odom, REP-105), with its conversions to and from 3D poses. The simulator's
// start pose, the stack's odometry and estimates and the harness's setting all use it.
#include <Eigen/Geometry>
#include <cmath>

namespace trimbot {

struct Pose2 {
  double x = 0.0, y = 0.0, yaw = 0.0;
};

// An angle, or the difference of two headings, brought to [-pi, pi].
inline double WrapAngle(double angle) { return std::remainder(angle, 2.0 * M_PI); }

// A planar pose as a 3D transform (z = 0), and the planar part of a 3D pose (heading of its x axis).
inline Eigen::Isometry3d ToIsometry(const Pose2& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << pose.x, pose.y, 0.0;
  T.linear() = Eigen::AngleAxisd(pose.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}
inline Pose2 ToPose2(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d x_axis = T.linear().col(0);
  return {T.translation().x(), T.translation().y(), std::atan2(x_axis.y(), x_axis.x())};
}

// A planar point given in the frame of `pose` (e.g. base_link), in the frame the pose is in.
inline Eigen::Vector2d FromFrame(const Pose2& pose, const Eigen::Vector2d& local) {
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  return {pose.x + c * local.x() - s * local.y(), pose.y + s * local.x() + c * local.y()};
}
// The inverse: a planar point of the pose's frame, in the frame of `pose`.
inline Eigen::Vector2d IntoFrame(const Pose2& pose, const Eigen::Vector2d& point) {
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  const Eigen::Vector2d d = point - Eigen::Vector2d(pose.x, pose.y);
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y()};
}

}  // namespace trimbot
