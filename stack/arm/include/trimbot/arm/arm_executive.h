#pragma once
// The arm's part of the mission: cutter poses to reach in turn, each planned from the measured
// joint state around what perception has seen, executed as joint position targets along the timed
// trajectory, and judged by the joint encoders (tracking error, settling at the end).
//
//   SetGoals(poses)  ->  waits for the perceived environment (SetPerceivedPoints, once)
//                    ->  per goal: plan (ArmPlanner) -> move -> settle -> result
//   Update(stamp)    ->  the arm command now (none while idle or done)
//
// The environment is the stereo points near the arm, in base_link: points of the robot's own body
// and of the ground are dropped (the ground is a plane), the rest are cells grown by a margin that
// covers the stereo's noise and the tracking error. Nothing here sees ground truth.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/arm/arm_planner.h"
#include "trimbot/messages/commands.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/robot_description.h"

namespace trimbot::arm {

struct ArmExecutiveParameters {
  ArmPlannerParameters planner;
  double cell = 0.02;               // m: octree cell of the perceived points
  double margin = 0.02;             // m: cells are grown by this (stereo noise)
  int min_points_per_cell = 2;      // fewer: a stray match, not a surface
  double max_point_sigma = 0.05;    // m: points less certain than this along their worst axis are dropped
  double reach = 1.3;               // m from the arm's base: farther points cannot be hit
  double ground_clearance = 0.02;   // m: the ground plane the arm must stay above; points below 2x it are ground
  double body_margin = 0.05;        // m: points within the base's outline grown by this are the robot itself
  double settle_tolerance = 0.002;  // rad: every joint within this of the trajectory's end
  double settle_timeout = 3.0;      // s after the trajectory's end
};

// How one goal went, as the stack knows it (encoders and its own kinematics).
struct ArmGoalResult {
  int goal = 0;
  bool reached = false;
  std::string failure;            // when not reached
  double start = 0.0, end = 0.0;  // s: planning began, result known
  int ik_solutions = 0, free_goals = 0;
  long validity_checks = 0;
  double planning_seconds = 0.0;    // wall clock
  double path_length = 0.0;         // rad, joint space
  double cutter_path_length = 0.0;  // m
  double motion_duration = 0.0;     // s: the trajectory's
  double tracking_error_max = 0.0;  // rad: measured joints against the trajectory, over the motion
  double position_error = 0.0;      // m: the cutter (by the encoders) from the goal at the end
  double orientation_error = 0.0;   // rad
};

class ArmExecutive {
 public:
  enum class Mode { kIdle, kWaitingForEnvironment, kMoving, kSettling, kDone };

  // `description` must outlive the executive.
  ArmExecutive(const robot::RobotDescription& description, const ArmExecutiveParameters& parameters);
  ~ArmExecutive();

  // Cutter poses in base_link, reached in order while the base stands still.
  void SetGoals(const std::vector<Eigen::Isometry3d>& cutter_poses);
  void SetJointState(const messages::ArmJointState& joints);
  // What stereo saw (base_link), replacing what it saw before (BuildPerceivedEnvironment); the
  // roadmap starts afresh.
  void SetPerceivedPoints(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Matrix3d>& covariances);
  bool WantsEnvironment() const { return mode_ == Mode::kWaitingForEnvironment && !environment_ready_; }
  std::optional<messages::ArmCommand> Update(double stamp);

  Mode mode() const { return mode_; }
  bool active() const { return mode_ != Mode::kIdle && mode_ != Mode::kDone; }
  int current_goal() const { return goal_; }
  int perceived_cells() const { return perceived_cells_; }
  // Results of the goals finished since the last call.
  std::vector<ArmGoalResult> TakeResults();
  // The joint target of the trajectory now (empty when not moving).
  const Eigen::VectorXd& target() const { return target_; }

 private:
  // Plans the current goal from the measured joints and starts moving; goals that cannot be
  // planned are finished at once with the reason, and the next is tried.
  void StartGoal(double stamp);
  // Records the current goal's result and moves on to the next (done after the last).
  void FinishGoal(double stamp, bool reached, const std::string& failure);

  ArmExecutiveParameters parameters_;
  ArmKinematics kinematics_;
  std::unique_ptr<robot::CollisionModel> collision_;
  std::unique_ptr<ArmPlanner> planner_;
  const robot::RobotDescription& description_;

  Mode mode_ = Mode::kIdle;
  std::vector<Eigen::Isometry3d> goals_;
  int goal_ = 0;
  std::optional<messages::ArmJointState> joints_;
  ArmPlan plan_;
  ArmGoalResult result_;
  double motion_start_ = 0.0;
  double settle_start_ = 0.0;
  bool environment_ready_ = false;
  Eigen::VectorXd target_;
  int perceived_cells_ = 0;
  std::vector<ArmGoalResult> finished_;
};

const char* ToString(ArmExecutive::Mode mode);

// The environment the planner avoids, from stereo points in base_link: the ground plane at
// ground_clearance, and octree cells of `cell` holding at least min_points_per_cell certain points
// within reach of the arm's base, outside the base's outline and above the ground, grown by
// `margin`. Replaces what `environment` held; returns the number of occupied cells.
int BuildPerceivedEnvironment(const robot::RobotDescription& description, const ArmExecutiveParameters& parameters,
                              const std::vector<Eigen::Vector3d>& points,
                              const std::vector<Eigen::Matrix3d>& covariances,
                              robot::CollisionEnvironment* environment);

}  // namespace trimbot::arm
