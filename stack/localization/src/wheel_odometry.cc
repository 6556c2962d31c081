#include "trimbot/stack/wheel_odometry.h"

#include <cmath>

namespace trimbot::stack {

void WheelOdometry::Update(const messages::WheelTicks& ticks) {
  if (!last_) {
    last_ = ticks;
    return;
  }
  const robot::WheelSpeeds rotation{static_cast<double>(ticks.left - last_->left) * radians_per_tick_,
                                    static_cast<double>(ticks.right - last_->right) * radians_per_tick_};
  const double distance = geometry_.LinearFromWheels(rotation);
  last_distance_ = distance;
  const double turn = geometry_.AngularFromWheels(rotation);
  const double heading = pose_.yaw + 0.5 * turn;
  pose_.x += distance * std::cos(heading);
  pose_.y += distance * std::sin(heading);
  pose_.yaw = WrapAngle(pose_.yaw + turn);
  const double dt = ticks.stamp - last_->stamp;
  if (dt > 0.0) {
    linear_velocity_ = distance / dt;
    angular_velocity_ = turn / dt;
  }
  last_ = ticks;
}

void GyroOdometry::AddYawRate(double stamp, double yaw_rate) {
  if (last_gyro_stamp_ >= 0.0 && stamp > last_gyro_stamp_) {
    pose_.yaw = WrapAngle(pose_.yaw + yaw_rate * (stamp - last_gyro_stamp_));
  }
  last_gyro_stamp_ = stamp;
}

void GyroOdometry::AddWheelTicks(const messages::WheelTicks& ticks) {
  wheels_.Update(ticks);
  const double distance = wheels_.last_distance();
  const double heading = heading_at_ticks_ + 0.5 * WrapAngle(pose_.yaw - heading_at_ticks_);
  pose_.x += distance * std::cos(heading);
  pose_.y += distance * std::sin(heading);
  heading_at_ticks_ = pose_.yaw;
}

}  // namespace trimbot::stack
