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
  const double turn = geometry_.AngularFromWheels(rotation);
  const double heading = pose_.yaw + 0.5 * turn;
  pose_.x += distance * std::cos(heading);
  pose_.y += distance * std::sin(heading);
  pose_.yaw = std::remainder(pose_.yaw + turn, 2.0 * M_PI);
  const double dt = ticks.stamp - last_->stamp;
  if (dt > 0.0) {
    linear_velocity_ = distance / dt;
    angular_velocity_ = turn / dt;
  }
  last_ = ticks;
}

}  // namespace trimbot::stack
