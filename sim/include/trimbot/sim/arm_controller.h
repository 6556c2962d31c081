#pragma once
// The arm's joint controller: turns position or velocity commands into position targets for the
// joint servos, clamped to the joint limits. (The arm's own gravity compensation is applied by the
// simulator, as the Kinova firmware does.)
#include <array>

#include "trimbot/messages/commands.h"

namespace trimbot::sim {

struct JointRange {
  bool limited = false;
  double lower = 0.0;
  double upper = 0.0;
};

class ArmController {
 public:
  using Joints = std::array<double, messages::kArmJoints>;
  ArmController(const Joints& initial_position, const std::array<JointRange, messages::kArmJoints>& ranges);
  void SetCommand(const messages::ArmCommand& command) { command_ = command; }
  // Position targets after dt.
  const Joints& Update(double dt);
  const Joints& target() const { return target_; }

 private:
  std::array<JointRange, messages::kArmJoints> ranges_;
  messages::ArmCommand command_;
  Joints target_;
};

}  // namespace trimbot::sim
