#include "trimbot/sim/base_controller.h"

#include <algorithm>

namespace trimbot::sim {
namespace {

double StepTowards(double current, double target, double max_step) {
  return current + std::clamp(target - current, -max_step, max_step);
}

}  // namespace

robot::WheelSpeeds BaseController::Update(double dt) {
  const double linear_target = std::clamp(command_.linear, -limits_.max_linear_speed, limits_.max_linear_speed);
  const double angular_target = std::clamp(command_.angular, -limits_.max_angular_speed, limits_.max_angular_speed);
  linear_ = StepTowards(linear_, linear_target, limits_.max_linear_acceleration * dt);
  angular_ = StepTowards(angular_, angular_target, limits_.max_angular_acceleration * dt);
  target_ = geometry_.FromTwist(linear_, angular_);
  return target_;
}

robot::WheelSpeeds BaseController::ActuatorSetpoints(const robot::WheelSpeeds& measured, double dt) {
  constexpr double kIntegralGain = 20.0;  // 1/s: removes a speed error in ~50 ms
  constexpr double kIntegralLimit = 2.0;  // rad/s, anti-windup
  integral_.left =
      std::clamp(integral_.left + kIntegralGain * (target_.left - measured.left) * dt, -kIntegralLimit, kIntegralLimit);
  integral_.right = std::clamp(integral_.right + kIntegralGain * (target_.right - measured.right) * dt, -kIntegralLimit,
                               kIntegralLimit);
  return {target_.left + integral_.left, target_.right + integral_.right};
}

}  // namespace trimbot::sim
