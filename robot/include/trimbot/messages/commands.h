#pragma once
// Commands: what the stack sends to the robot's actuators.
#include <algorithm>
#include <array>
#include <iterator>
#include <optional>
#include <vector>

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

// What the stack asks of the camera ring for the frame triggered at a stamp: which cameras, at
// what resolution. The driver delivers (the simulator renders) only these; an empty request
// skips the frame. The real ring's driver would select and bin the same way.
struct RingRequest {
  std::vector<int> cameras;       // rig camera indices, ascending, no duplicates
  double resolution_scale = 1.0;  // fraction of the calibrated image size (0.5: 376x240)
  bool empty() const { return cameras.empty(); }
};

// One frame serving both requests: the union of their cameras at the finer resolution.
inline RingRequest Merge(const RingRequest& a, const RingRequest& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  RingRequest out;
  std::set_union(a.cameras.begin(), a.cameras.end(), b.cameras.begin(), b.cameras.end(),
                 std::back_inserter(out.cameras));
  out.resolution_scale = std::max(a.resolution_scale, b.resolution_scale);
  return out;
}

// What the robot software sends to the actuators in one update: only the commands that changed
// (an empty field leaves the actuator on its last command).
struct RobotCommands {
  std::optional<BaseVelocityCommand> base;
  std::optional<ArmCommand> arm;
  std::optional<CutterCommand> cutter;
};

}  // namespace trimbot::messages
