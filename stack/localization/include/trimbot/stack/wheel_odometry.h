#pragma once
// Dead reckoning from wheel encoder counts: the odom -> base_link pose of REP-105.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <optional>

#include "trimbot/common/pose2.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/diff_drive.h"

namespace trimbot::stack {

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
