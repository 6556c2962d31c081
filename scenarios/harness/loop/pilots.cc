#include "loop/pilots.h"

namespace trimbot::scenarios {

void FeedStack(stack::RobotStack& stack, const sim::SensorOutputs& sensors,
               const std::vector<messages::PoseFix>& pose_fixes) {
  for (const auto& imu : sensors.imu) stack.Add(imu);
  for (const auto& ticks : sensors.wheel_ticks) stack.Add(ticks);
  for (const auto& joints : sensors.arm_joints) stack.Add(joints);
  for (const auto& fix : pose_fixes) stack.Add(fix);
  if (sensors.ring) stack.Add(*sensors.ring);
}

messages::RobotCommands StackPilot::Step(double time, const sim::SensorOutputs& sensors,
                                         const std::vector<messages::PoseFix>& pose_fixes) {
  FeedStack(stack_, sensors, pose_fixes);
  return stack_.Update(time);
}

bool StackPilot::Finished() const {
  const stack::MissionState mission = stack_.telemetry().mission;
  return mission == stack::MissionState::kDone || mission == stack::MissionState::kFailed;
}

messages::RobotCommands DrivePlanPlayer::Step(double time, const sim::SensorOutputs& sensors,
                                              const std::vector<messages::PoseFix>& pose_fixes) {
  if (listener_ != nullptr) {
    FeedStack(*listener_, sensors, pose_fixes);
    listener_->Update(time);
  }
  finished_ = time >= duration_ - 1e-9;
  const DriveSegment& segment = plan_.SegmentAt(time);
  messages::RobotCommands commands;
  commands.base = messages::BaseVelocityCommand{segment.linear, segment.angular};
  if (segment.arm) {
    messages::ArmCommand arm;
    arm.position = *segment.arm;
    commands.arm = arm;
  }
  commands.cutter = messages::CutterCommand{segment.cutter};
  return commands;
}

}  // namespace trimbot::scenarios
