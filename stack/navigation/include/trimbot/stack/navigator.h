#pragma once
// Goal-to-goal navigation on the pose estimate: plan over the prior map, follow the path, and when
// the robot (by its estimate) gets too close to an obstacle of the map, stop, back off and plan
// again - the recovery behaviour of the real robot's navigation. A system with explicit input
// (time, pose estimate), output (base velocity command) and state (goal, path, mode); the events it
// reports (goal reached, replans, recoveries, failures) go to the evaluation.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "trimbot/messages/commands.h"
#include "trimbot/stack/global_planner.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/stack/path_follower.h"
#include "trimbot/stack/wheel_odometry.h"

namespace trimbot::stack {

struct NavigatorParameters {
  PlannerParameters planner;         // holds the footprint
  FollowerParameters follower;
  double stop_clearance = 0.03;      // m: footprint this close to the map's obstacles -> stop
  double resume_clearance = 0.2;     // m: back off until this much is free again
  double backoff_speed = 0.1;        // m/s
  double max_backoff = 0.6;          // m
  double replan_deviation = 0.6;     // m off the path -> plan again
  int max_recoveries_per_goal = 5;
  int max_plan_failures = 3;         // per goal, then the goal is given up
};

struct NavigationEvent {
  enum class Type { kPlanned, kPlanFailed, kGoalReached, kGoalFailed, kObstacleStop, kRecovered };
  double stamp = 0.0;
  Type type = Type::kPlanned;
  int goal = 0;
  std::string detail;
};
const char* ToString(NavigationEvent::Type type);

class Navigator {
 public:
  enum class Mode { kIdle, kFollowing, kBackingOff, kDone, kFailed };

  Navigator(const OccupancyGrid& map, const NavigatorParameters& parameters);

  void SetGoals(const std::vector<Eigen::Vector2d>& goals);
  messages::BaseVelocityCommand Update(double stamp, const Pose2& estimate);

  // Smallest distance from the footprint at `pose` to an obstacle of the map (negative: overlap).
  double FootprintClearance(const Pose2& pose) const;

  Mode mode() const { return mode_; }
  int current_goal() const { return goal_; }
  const std::vector<Eigen::Vector2d>& path() const { return follower_.path(); }
  // Events since the last call.
  std::vector<NavigationEvent> TakeEvents();
  // Wall-clock seconds spent in the global planner since construction.
  double planning_seconds() const { return planning_seconds_; }

 private:
  void PlanToCurrentGoal(double stamp, const Pose2& estimate);
  void GiveUpGoal(double stamp, const std::string& why);
  void Emit(double stamp, NavigationEvent::Type type, const std::string& detail = {});

  const OccupancyGrid& map_;
  NavigatorParameters parameters_;
  GlobalPlanner planner_;
  PathFollower follower_;
  std::vector<Eigen::Vector2d> goals_;
  int goal_ = 0;
  Mode mode_ = Mode::kIdle;
  int recoveries_ = 0;
  int plan_failures_ = 0;
  Eigen::Vector2d backoff_start_ = Eigen::Vector2d::Zero();
  std::vector<NavigationEvent> events_;
  double planning_seconds_ = 0.0;
};

}  // namespace trimbot::stack
