#include "stack_state.h"

#include "trimbot/robot/robot_parameters.h"

namespace trimbot::stack {

StackState::StackState(const robot::RobotFiles& files, const StackParameters& parameters)
    : description(robot::RobotDescription::Load(files.urdf)),
      rig(robot::CameraRig::LoadKalibr(files.camchain, description.FramePose(robot::RobotFrames::CameraOptical(0)))),
      outline(description.BaseOutline().first, description.BaseOutline().second),
      ticks_per_revolution(robot::RobotParameters::Load(files.robot_parameters).wheel_encoders.ticks_per_revolution),
      odometry(description.drive(), ticks_per_revolution),
      servo_odometry(description.drive(), ticks_per_revolution),
      ekf(parameters.ekf, description.drive(), ticks_per_revolution),
      arm_axis(description.FramePose(robot::RobotFrames::kCameraRing).translation().head<2>()),
      arm(description, parameters.arm),
      trim(description, parameters.Trim()),
      mission(parameters, arm_axis, ekf, servo_odometry, &arm, &trim) {}

}  // namespace trimbot::stack
