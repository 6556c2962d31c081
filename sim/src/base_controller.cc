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
  return geometry_.FromTwist(linear_, angular_);
}

}  // namespace trimbot::sim
