#include "trimbot/sim/arm_controller.h"

#include <algorithm>

namespace trimbot::sim {

ArmController::ArmController(const Joints& initial_position, const std::array<JointRange, messages::kArmJoints>& ranges)
    : ranges_(ranges), target_(initial_position) {
  command_.mode = messages::ArmCommand::Mode::kPosition;
  command_.position = initial_position;
}

const ArmController::Joints& ArmController::Update(double dt) {
  for (size_t i = 0; i < target_.size(); ++i) {
    double target = command_.mode == messages::ArmCommand::Mode::kPosition ? command_.position[i]
                                                                           : target_[i] + command_.velocity[i] * dt;
    if (ranges_[i].limited) target = std::clamp(target, ranges_[i].lower, ranges_[i].upper);
    target_[i] = target;
  }
  return target_;
}

}  // namespace trimbot::sim
