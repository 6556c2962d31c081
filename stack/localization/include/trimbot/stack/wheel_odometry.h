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

class WheelOdometry {
 public:
  WheelOdometry(const robot::DiffDriveGeometry& geometry, int ticks_per_revolution)
      : geometry_(geometry), radians_per_tick_(2.0 * 3.14159265358979323846 / ticks_per_revolution) {}

  // Integrates the motion since the previous reading (midpoint rule on the heading).
  void Update(const messages::WheelTicks& ticks);
  const Pose2& pose() const { return pose_; }
  double linear_velocity() const { return linear_velocity_; }
  double angular_velocity() const { return angular_velocity_; }

 private:
  robot::DiffDriveGeometry geometry_;
  double radians_per_tick_;
  std::optional<messages::WheelTicks> last_;
  Pose2 pose_;
  double linear_velocity_ = 0.0;
  double angular_velocity_ = 0.0;
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
  WheelOdometry wheels_;        // its distance travelled; its heading is not used
  double last_gyro_stamp_ = -1.0;
  double heading_at_ticks_ = 0.0;  // at the previous wheel reading
  Pose2 pose_;
};

}  // namespace trimbot::stack
