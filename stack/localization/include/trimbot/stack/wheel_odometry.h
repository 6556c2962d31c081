#pragma once
// Dead reckoning from wheel encoder counts: the odom -> base_link pose of REP-105.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <optional>

#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/diff_drive.h"

namespace trimbot::stack {

struct Pose2 {
  double x = 0.0, y = 0.0, yaw = 0.0;
};

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

class WheelOdometry {
 public:
  WheelOdometry(const robot::DiffDriveGeometry& geometry, int ticks_per_revolution)
      : geometry_(geometry), radians_per_tick_(2.0 * 3.14159265358979323846 / ticks_per_revolution) {}

  // Integrates the motion since the previous reading (midpoint rule on the heading).
  void Update(const messages::WheelTicks& ticks);
  const Pose2& pose() const { return pose_; }
  double linear_velocity() const { return linear_velocity_; }
  double angular_velocity() const { return angular_velocity_; }
  // m along base_link's x in the last update (negative: backwards).
  double last_distance() const { return last_distance_; }

 private:
  robot::DiffDriveGeometry geometry_;
  double radians_per_tick_;
  std::optional<messages::WheelTicks> last_;
  Pose2 pose_;
  double linear_velocity_ = 0.0;
  double angular_velocity_ = 0.0;
  double last_distance_ = 0.0;
};

// Wheel distance with the gyro's heading, in a local frame that starts at the origin. On grass the
// wheels slip sideways in turns on the spot (wheel odometry lost ~10 deg of heading in a few
// turns), the gyro does not: the visual servo tracks the bush in this frame. The gyro's bias comes
// from the caller (the EKF estimates it).
class GyroOdometry {
 public:
  GyroOdometry(const robot::DiffDriveGeometry& geometry, int ticks_per_revolution)
      : wheels_(geometry, ticks_per_revolution) {}
  // The yaw rate about base_link's z (bias removed), integrated into the heading.
  void AddYawRate(double stamp, double yaw_rate);
  // Travel since the previous reading, along the mean heading between the two readings.
  void AddWheelTicks(const messages::WheelTicks& ticks);
  const Pose2& pose() const { return pose_; }

 private:
  WheelOdometry wheels_;  // its distance per reading; its heading is not used
  double last_gyro_stamp_ = -1.0;
  double heading_at_ticks_ = 0.0;  // at the previous wheel reading
  Pose2 pose_;
};

}  // namespace trimbot::stack
