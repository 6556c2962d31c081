#pragma once
// Commands: what the stack sends to the robot's actuators.
#include <array>
#include <optional>

namespace trimbot::messages {

// Body velocity of the base in base_link; the base controller turns it into wheel speeds and
// applies the drive's acceleration limits.
struct BaseVelocityCommand {
  double linear = 0.0;   // m/s, +x forward
  double angular = 0.0;  // rad/s, +z counter-clockwise
};

constexpr int kArmJoints = 6;

// Joint-space target for the arm. In kPosition mode the joints servo to `position`; in kVelocity
// mode they move at `velocity` (the controller integrates it into a moving position target).
struct ArmCommand {
  enum class Mode { kPosition, kVelocity };
  Mode mode = Mode::kPosition;
  std::array<double, kArmJoints> position{};  // rad
  std::array<double, kArmJoints> velocity{};  // rad/s
};

struct CutterCommand {
  bool on = false;
};

// What the robot software sends to the actuators in one update: only the commands that changed
// (an empty field leaves the actuator on its last command).
struct RobotCommands {
  std::optional<BaseVelocityCommand> base;
  std::optional<ArmCommand> arm;
  std::optional<CutterCommand> cutter;
};

}  // namespace trimbot::messages
