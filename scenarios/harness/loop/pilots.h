#pragma once
// The pilots the loop can run: the robot software (RobotStack) driving its mission, and a
// drive-plan player for open-loop drives, which may carry a RobotStack that only listens
// (estimates and perceives, commands nothing) so a drive records what the stack believed.
#include <vector>

#include "loop/closed_loop.h"
#include "loop/drive_plan.h"
#include "trimbot/stack/robot_stack.h"

namespace trimbot::scenarios {

// Feeds one step's messages to the stack in the order a driver would deliver them.
void FeedStack(stack::RobotStack& stack, const sim::SensorOutputs& sensors,
               const std::vector<messages::PoseFix>& pose_fixes);

class StackPilot : public Pilot {
 public:
  explicit StackPilot(stack::RobotStack& stack) : stack_(stack) {}
  messages::RobotCommands Step(double time, const sim::SensorOutputs& sensors,
                               const std::vector<messages::PoseFix>& pose_fixes) override;
  messages::RingRequest RingRequestAt(double time) const override { return stack_.RingRequestAt(time); }
  bool Finished() const override;
  const stack::Telemetry* telemetry() const override { return &stack_.telemetry(); }

 private:
  stack::RobotStack& stack_;
};

class DrivePlanPlayer : public Pilot {
 public:
  // `listener` (optional) gets every sensor message; its commands are ignored.
  DrivePlanPlayer(const DrivePlan& plan, double duration, stack::RobotStack* listener = nullptr)
      : plan_(plan), duration_(duration), listener_(listener) {}
  messages::RobotCommands Step(double time, const sim::SensorOutputs& sensors,
                               const std::vector<messages::PoseFix>& pose_fixes) override;
  messages::RingRequest RingRequestAt(double time) const override {
    return listener_ != nullptr ? listener_->RingRequestAt(time) : messages::RingRequest{};
  }
  bool Finished() const override { return finished_; }
  const stack::Telemetry* telemetry() const override { return listener_ ? &listener_->telemetry() : nullptr; }

 private:
  const DrivePlan& plan_;
  double duration_;
  stack::RobotStack* listener_;
  bool finished_ = false;
};

}  // namespace trimbot::scenarios
