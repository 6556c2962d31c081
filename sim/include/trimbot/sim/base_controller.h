#pragma once
// The base's motor controller: takes the commanded body velocity, limits speed and acceleration as
// the drive firmware does, and gives the wheel speed targets for the wheel motors.
#include "trimbot/messages/commands.h"
#include "trimbot/robot/diff_drive.h"
#include "trimbot/robot/robot_parameters.h"

namespace trimbot::sim {

class BaseController {
 public:
  BaseController(const robot::DiffDriveGeometry& geometry, const robot::DriveLimits& limits)
      : geometry_(geometry), limits_(limits) {}
  void SetCommand(const messages::BaseVelocityCommand& command) { command_ = command; }
  // Advances the rate limiter by dt and returns the wheel speed targets.
  robot::WheelSpeeds Update(double dt);
  double linear() const { return linear_; }
  double angular() const { return angular_; }

 private:
  robot::DiffDriveGeometry geometry_;
  robot::DriveLimits limits_;
  messages::BaseVelocityCommand command_;
  double linear_ = 0.0;
  double angular_ = 0.0;
};

}  // namespace trimbot::sim
