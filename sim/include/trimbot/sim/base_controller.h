#pragma once
// The base's motor controller: takes the commanded body velocity, limits speed and acceleration as
// the drive firmware does, and runs a speed loop per wheel. MuJoCo's velocity actuator is the
// proportional part (stable under the implicit integrator); the integral part here removes the
// steady-state error that tyre scrub and rolling resistance would otherwise leave.
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
  // Setpoints for the wheels' velocity actuators: target plus the integral correction, given the
  // measured wheel speeds.
  robot::WheelSpeeds ActuatorSetpoints(const robot::WheelSpeeds& measured, double dt);
  double linear() const { return linear_; }
  double angular() const { return angular_; }

 private:
  robot::DiffDriveGeometry geometry_;
  robot::DriveLimits limits_;
  messages::BaseVelocityCommand command_;
  double linear_ = 0.0;
  double angular_ = 0.0;
  robot::WheelSpeeds target_;
  robot::WheelSpeeds integral_;  // rad/s added to the setpoints
};

}  // namespace trimbot::sim
