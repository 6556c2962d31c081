#pragma once
// The robot software as one system: time-stamped sensor messages in, actuator commands out, and a
// telemetry record of what it believes and does. It is built from the robot's files only (URDF,
// camera calibration, robot parameters, stack parameters) and owns its components - wheel
// odometry, the EKF, the navigator with its planner and path follower, local fusion - and their
// scheduling; which components run is configuration (StackParameters), not the caller's wiring.
// The components that use the camera ring's frames (visual localization, obstacles, bush sighting,
// the arm's surroundings, local fusion) run on the frames they are due for (RingRequestAt, Add);
// the mission - navigator, bush servo, arm - runs on control ticks (Update).
// Nothing here knows whether the sensors are simulated: the same object could run on the robot.
//
// Use:  RobotStack stack(files, parameters, seed);
//       stack.SetInitialPose(0, believed_start);  stack.SetMap(map_yaml);  stack.SetGoals(goals);
//       (a goal is a point, or Goal::ApproachBush: by map to ~1 m, then visual servoing, or
//        Goal::TrimBush: approached so, then trimmed from the standoff)
//       per sensor message: stack.Add(message);   then: commands = stack.Update(now);
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/messages/commands.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/perception/bush_estimator.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/stack/goal.h"
#include "trimbot/stack/stack_parameters.h"
#include "trimbot/stack/telemetry.h"
#include "trimbot/visual_localization/localizer.h"

namespace trimbot::stack {

// The stack's visual localizer for `rig` against the map file, configured by `parameters` (one
// place: the stack and the offline localization benchmarks use the same). Throws InputError naming
// the file if it is not a map or was made for another rig or descriptor.
std::unique_ptr<visual_localization::VisualLocalizer> MakeVisualLocalizer(
    const std::string& map_path, const VisualLocalizationParameters& parameters, const robot::CameraRig& rig);

class RobotStack {
 public:
  // Whether a stack with `parameters` on this mission uses the ring's images (the driver must then
  // deliver what RingRequestAt asks for): its parameters say so, a goal approaches a bush, or the
  // arm has goals (it perceives its surroundings).
  static bool UsesRingImages(const StackParameters& parameters, const std::vector<Goal>& goals, bool arm_goals = false);

  // `seed` seeds the stack's randomized algorithms (the planner's RRT*): same seed, same plans.
  // Throws InputError naming the file and key when a file is missing or malformed.
  RobotStack(const robot::RobotFiles& files, const StackParameters& parameters, std::uint64_t seed);
  ~RobotStack();
  RobotStack(const RobotStack&) = delete;
  RobotStack& operator=(const RobotStack&) = delete;

  // Mission inputs, from the operator.
  // Where the robot was put down, as far as the operator knows (the EKF starts here with the
  // parameters' initial_pose_sigma); the odom frame starts here too.
  void SetInitialPose(double stamp, const Pose2& believed_pose);
  // The prior map of the garden (map_server YAML + PNG); needed before goals.
  void SetMap(const std::string& map_yaml);
  // The visual localization map (trimbot map build); needed with localization: visual. Throws
  // InputError naming the file if it is not a map or was made for another camera rig.
  void SetVisualMap(const std::string& map_path);
  // Goals in the map frame, visited in order; navigation starts with the next update. Needs the
  // prior map, and with localization: visual the visual map (std::logic_error otherwise).
  void SetGoals(const std::vector<Goal>& goals);
  // Cutter poses in base_link for the arm, reached in turn once the navigation goals (if any) are
  // done, while the base stands. The arm plans around what the ring's stereo pairs see then.
  void SetArmGoals(const std::vector<Eigen::Isometry3d>& cutter_poses);
  // Stored cutting paths for trim goals (trimbot trim precompute): the nearest is adapted instead
  // of solving the path in full. Throws InputError naming the file when it is not a cutting path
  // database or was made for another arm.
  void SetCuttingPathDatabase(const std::string& path);
  // Drive by hand: the command passes through to the base (navigation stays idle); the stack
  // still estimates its pose and runs perception.
  void SetTeleopCommand(const messages::BaseVelocityCommand& command);

  // Sensor inputs, in time order per sensor.
  void Add(const messages::ImuSample& imu);
  void Add(const messages::WheelTicks& ticks);
  void Add(const messages::ArmJointState& joints);
  void Add(const messages::RingFrame& frame);
  void Add(const messages::PoseFix& fix);  // used when localization is simulated_pose_fixes

  // What the components would use of a ring frame exposed at `stamp`: the cameras and resolution
  // (empty: nothing; a driver skips the frame or the cameras not named).
  messages::RingRequest RingRequestAt(double stamp) const;

  // Runs the components due at `stamp` (the latest sensor time) and returns the commands.
  messages::RobotCommands Update(double stamp);

  const Telemetry& telemetry() const { return telemetry_; }
  // The navigator's costmap on the prior map's cells (CV_8U, row 0 = the map's top): 0 free,
  // 128 an obstacle of the prior map, 255 an obstacle only perception has seen. Empty before SetMap.
  cv::Mat CostmapLayers() const;
  const StackParameters& parameters() const { return parameters_; }

 private:
  // Who commands the base this control tick: teleoperation, the bush servo, nothing (visual
  // localization lost) or the navigator.
  void RunNavigation(double stamp, messages::RobotCommands* commands);

  StackParameters parameters_;
  struct Components;  // the parts the components share (StackState) and the ring-frame components
  std::unique_ptr<Components> components_;
  Telemetry telemetry_;
  double next_control_ = 0.0;
  std::optional<messages::BaseVelocityCommand> teleop_;
};

}  // namespace trimbot::stack
