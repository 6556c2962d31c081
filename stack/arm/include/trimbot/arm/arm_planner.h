#pragma once
// Collision-free arm motions in joint space (OMPL), checked by the robot's FCL collision model
// against itself and the environment it has been given, timed within the URDF's velocity limits.
//
//   PlanToPose:     every inverse-kinematics solution of the cutter pose that is collision-free is
//                   a goal; RRTConnect (or a LazyPRM whose roadmap is kept between queries while the
//                   environment stays, e.g. near one bush) joins the start to the first it reaches;
//                   the path is shortcut-simplified and timed.
//   CartesianPass:  the cutter along a straight line (a cut), by inverse kinematics from the
//                   previous step's solution, refused when the branch jumps or a step collides.
//
// The continuous joints are SO(2) for the planner (a path may cross pi); the trajectory is unwrapped
// from the start's values so a joint controller never turns the long way. Deterministic: the
// budgets are iterations, not seconds, and OMPL's generator is seeded by the stack.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/arm/arm_kinematics.h"
#include "trimbot/robot/collision_model.h"

namespace trimbot::arm {

struct ArmPlannerParameters {
  enum class Algorithm { kRrtConnect, kLazyPrm };
  Algorithm algorithm = Algorithm::kRrtConnect;
  int max_iterations = 20000;             // planner iterations per query (a budget that is the same on every machine)
  double collision_step = 0.02;           // rad: motions are checked at this joint-space spacing
  double velocity_scale = 0.5;            // fraction of the URDF's joint velocity limits
  double acceleration = 1.5;              // rad/s^2 per joint
  double cartesian_step = 0.005;          // m of cutter travel between inverse-kinematics steps of a pass
  double cartesian_max_joint_step = 0.1;  // rad per step: more means the arm would switch branch
  // m the arm keeps from the robot's own body (the CollisionModel its planner checks is built with it).
  double body_clearance = 0.01;
  IkOptions ik;
};

// Positions (and velocities) of the six joints over time; continuous joints unwrapped.
struct JointTrajectory {
  std::vector<double> times;                // s from the start, ascending, first 0
  std::vector<Eigen::VectorXd> positions;   // rad
  std::vector<Eigen::VectorXd> velocities;  // rad/s
  double duration() const { return times.empty() ? 0.0 : times.back(); }
  // Position and velocity at `t` (clamped to the ends).
  void Sample(double t, Eigen::VectorXd* position, Eigen::VectorXd* velocity) const;
};

struct ArmPlan {
  bool ok = false;
  std::string failure;                     // when not ok: why (unreachable, every solution collides, no path)
  std::vector<Eigen::VectorXd> waypoints;  // the simplified path, unwrapped from the start
  JointTrajectory trajectory;
  int ik_solutions = 0;             // of the goal pose
  int free_goals = 0;               // of which collision-free
  double path_length = 0.0;         // rad: joint-space length of the waypoints
  double cutter_path_length = 0.0;  // m: the cutter's travel along the trajectory
  long validity_checks = 0;
  double planning_seconds = 0.0;  // wall clock (for reports and benchmarks only)
};

class ArmPlanner {
 public:
  // `collision` holds the environment (base_link frame); the planner reads it at each query.
  ArmPlanner(const ArmKinematics& kinematics, const robot::CollisionModel& collision,
             const ArmPlannerParameters& parameters);
  ~ArmPlanner();

  bool Valid(const Eigen::VectorXd& q) const;
  ArmPlan PlanToJoints(const Eigen::VectorXd& start, const Eigen::VectorXd& goal);
  ArmPlan PlanToPose(const Eigen::VectorXd& start, const Eigen::Isometry3d& cutter);
  // The cutter from where `start` puts it to `to` along a straight line (orientation interpolated).
  ArmPlan CartesianPass(const Eigen::VectorXd& start, const Eigen::Isometry3d& to);
  // The environment changed: the LazyPRM's roadmap no longer holds.
  void ResetRoadmap();

  const ArmPlannerParameters& parameters() const { return parameters_; }

 private:
  ArmPlan Plan(const Eigen::VectorXd& start, const std::vector<Eigen::VectorXd>& goals, ArmPlan plan);
  // The plan's waypoints (start, then `states` unwrapped from it), trajectory and lengths.
  void SetWaypoints(const Eigen::VectorXd& start, const std::vector<Eigen::VectorXd>& states, ArmPlan* plan) const;
  // Marks a plan with its trajectory done: its lengths.
  void Finish(ArmPlan* plan) const;
  Eigen::VectorXd VelocityLimits() const;  // rad/s: the URDF's, scaled
  // Of all solutions of `pose`, the one nearest `near` (continuous joints unwrapped to it).
  std::optional<Eigen::VectorXd> NearestSolution(const Eigen::Isometry3d& pose, const Eigen::VectorXd& near,
                                                 std::string* failure) const;

  const ArmKinematics& kinematics_;
  const robot::CollisionModel& collision_;
  ArmPlannerParameters parameters_;
  struct Ompl;
  std::unique_ptr<Ompl> ompl_;
};

// Times a joint-space path through `waypoints` (straight lines between them), every joint within
// `velocity_limits` and `acceleration`, with a trapezoidal speed profile from rest to rest over each
// stretch between stops: the arm stops at waypoint k when stops[k] (at every one when `stops` is
// empty; always at the ends). Waypoints it passes through should lie on a smooth path (the steps of a
// Cartesian line): the profile does not slow for corners.
JointTrajectory TimeParameterize(const std::vector<Eigen::VectorXd>& waypoints, const Eigen::VectorXd& velocity_limits,
                                 double acceleration, const std::vector<bool>& stops = {}, double sample_period = 0.02);

// The joint vectors after `from` up to `to` along the straight joint-space line between them, no
// joint turning more than `step` from one to the next: the states a motion is checked at.
std::vector<Eigen::VectorXd> JointSteps(const Eigen::VectorXd& from, const Eigen::VectorXd& to, double step);

// The poses after `from` up to `to` along the straight line between them (position linearly,
// orientation by the shortest rotation), `step` metres of travel or 10 * `step` radians of turn
// apart, whichever makes more: the steps of a Cartesian pass.
std::vector<Eigen::Isometry3d> PosesAlongLine(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double step);

}  // namespace trimbot::arm
