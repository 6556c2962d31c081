#include "stack_state.h"

#include "trimbot/robot/robot_parameters.h"
#include "trimbot/visual_localization/localizer.h"

namespace trimbot::stack {
namespace {

// The EKF's model of its fix source. The visual localizer's fixes share the map's error with the
// fixes taken near them: its covariance floor stands for that error (the Gauss-Newton part is the
// fix's own), and fixes share map points while their retrieval discs (prior_radius) overlap. The
// test fixture's fixes and no fixes at all share nothing.
EkfParameters EkfForSource(const StackParameters& parameters) {
  EkfParameters ekf = parameters.ekf;
  if (parameters.localization == LocalizationSource::kVisual) {
    ekf.shared_fix_error_sigma = visual_localization::LocalizerOptions{}.min_position_sigma;
    ekf.shared_fix_error_distance = parameters.visual.prior_radius;
  } else {
    ekf.shared_fix_error_sigma = 0.0;
  }
  return ekf;
}

}  // namespace

StackState::StackState(const robot::RobotFiles& files, const StackParameters& parameters)
    : description(robot::RobotDescription::Load(files.urdf)),
      rig(robot::CameraRig::LoadKalibr(files.camchain, description.FramePose(robot::RobotFrames::CameraOptical(0)))),
      ticks_per_revolution(robot::RobotParameters::Load(files.robot_parameters).wheel_encoders.ticks_per_revolution),
      odometry(description.drive(), ticks_per_revolution),
      servo_odometry(description.drive(), ticks_per_revolution),
      ekf(EkfForSource(parameters), description.drive(), ticks_per_revolution),
      arm_axis(description.FramePose(robot::RobotFrames::kCameraRing).translation().head<2>()),
      arm(description, parameters.arm),
      mission(parameters, arm_axis, ekf, servo_odometry, &arm) {}

}  // namespace trimbot::stack
