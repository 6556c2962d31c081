#pragma once
// The stack's mission: the operator's goals, visited in order, then the arm's goals while the base
// stands. The navigator drives to point goals by map; a bush goal is driven to by map as far as an
// approach point in front of the bush (one segment: the goals up to and including it), then
// reached by visual servoing on the bush (BushServo, fed by the bush sighting), after which the
// next segment starts.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "trimbot/arm/arm_executive.h"
#include "trimbot/messages/commands.h"
#include "trimbot/stack/bush_servo.h"
#include "trimbot/stack/ekf.h"
#include "trimbot/stack/goal.h"
#include "trimbot/stack/navigator.h"
#include "trimbot/stack/stack_parameters.h"
#include "trimbot/stack/telemetry.h"
#include "trimbot/stack/wheel_odometry.h"
#include "trimbot/trimming/trim_executive.h"

namespace trimbot::stack {

bool HasBushGoal(const std::vector<Goal>& goals);
bool HasTrimGoal(const std::vector<Goal>& goals);

class Mission {
 public:
  // Reads the pose estimate and the servo's odometry, and drives the arm; all outlive the mission.
  Mission(const StackParameters& parameters, const Eigen::Vector2d& arm_axis, const Ekf& ekf,
          const GyroOdometry& servo_odometry, arm::ArmExecutive* arm, trimming::TrimExecutive* trim);

  // Replaces the goals, from the first; StartSegment gives them to the navigator.
  void SetGoals(const std::vector<Goal>& goals);
  // Gives the navigator the goals from the next one up to the next bush goal (its approach point),
  // from the robot's estimated position, and the servo that bush.
  void StartSegment(Navigator* navigator);
  void SetArmGoals(const std::vector<Eigen::Isometry3d>& cutter_poses);

  // Per control tick (RobotStack::RunNavigation), after the navigator's update: marks the bush
  // goal's approach point reached in its events (telemetry->events) and starts the servo there.
  void HandleNavigationEvents(double stamp, Telemetry* telemetry);
  // Per control tick instead of the navigator while servoing: the servo's command. The bush goal
  // is reached or failed here; once reached, the next segment starts.
  void RunBushServo(double stamp, Navigator* navigator, messages::RobotCommands* commands, Telemetry* telemetry);
  // Per control tick instead of the navigator while trimming: the base stands for the scan,
  // advances to the trim's standoff once the target is fitted, and stands while the trim commands
  // the arm and the cutter. Once the trim is over, the next segment starts.
  void RunTrim(double stamp, Navigator* navigator, messages::RobotCommands* commands, Telemetry* telemetry);
  // Per control tick, after the base's command: the mission's state, current goal and bush approach.
  void UpdateTelemetry(const Navigator& navigator, Telemetry* telemetry);
  // Per control tick with arm goals, after the base's: once the navigation goals are done, the
  // arm's command.
  void RunArm(double stamp, messages::RobotCommands* commands, Telemetry* telemetry);

  // The current segment's bush goal (index into the goals; -1: none) and the servo approaching it.
  int bush_goal() const { return bush_goal_; }
  const Goal& goal(int index) const { return goals_[static_cast<std::size_t>(index)]; }
  const BushServo& servo() const { return servo_; }
  BushServo& servo() { return servo_; }
  // The servo expects the bush goal's bush where the map has it, through the pose estimate now.
  void ExpectBush();
  // A frame the bush was looked for in; `tracked`: the servo's track took its centre.
  void CountSighting(bool tracked);
  // The map pose of the servo's frame (GyroOdometry), by the EKF's estimate now.
  Eigen::Isometry3d MapFromServoFrame() const;

  bool servoing() const { return servoing_; }
  bool trimming() const { return trimming_; }
  bool has_arm_goals() const { return arm_goals_; }
  // No navigation goals, or they are done (the arm's goals come after them).
  bool NavigationGoalsDone() const;

 private:
  // Straight ahead on the servo's odometry from the approach's standoff to the trim's (closer: the
  // arm must reach round the bush); true once there (the base commanded to stop).
  bool AdvanceToTrim(messages::RobotCommands* commands);
  // base_link's position from which, turned to face the bush, the arm's axis is approach_margin
  // beyond the standoff.
  Eigen::Vector2d ApproachPoint(const Goal& goal, const Eigen::Vector2d& from, const Navigator& navigator) const;
  void FinishBushGoal(double stamp, bool reached, const std::string& detail, Navigator* navigator,
                      Telemetry* telemetry);
  // The bush goal's bush as a target in base_link (the servo's track, the survey's shape and yaw).
  void StartTrim(double stamp);

  const StackParameters& parameters_;
  Eigen::Vector2d arm_axis_;
  const Ekf& ekf_;
  const GyroOdometry& servo_odometry_;
  arm::ArmExecutive* arm_;
  trimming::TrimExecutive* trim_;
  BushServo servo_;
  // Goals before next_goal_ are done; bush_goal_ is the bush goal of the current segment (-1:
  // none), servoing_ whether its visual servoing has started.
  std::vector<Goal> goals_;
  int next_goal_ = 0;
  int bush_goal_ = -1;
  double approach_side_ = 0.0;  // rad, map: the bearing from the bush goal's centre to its approach point
  bool servoing_ = false;
  bool trimming_ = false;          // from the bush approach's end to the trim's
  Pose2 advance_from_;             // the servo frame's pose where the approach ended (the scan's)
  double advance_stopped_ = -1.0;  // s: stopped at the trim's standoff (-1: not yet)
  bool failed_ = false;
  BushApproachStatus bush_status_;
  bool arm_goals_ = false;                    // SetArmGoals was given goals
  MissionState state_ = MissionState::kIdle;  // as reported in the telemetry
};

}  // namespace trimbot::stack
