#pragma once
// Goal-to-goal navigation on the pose estimate: plan over the costmap (the prior map plus the
// obstacles perception has seen, SetCostmap), follow the path, plan again when what is seen
// blocks it, and when the robot (by its estimate) gets too close to an obstacle, stop, back off
// the way it came and plan again - the recovery behaviour of the real robot's navigation. Every check is of the
// base's real outline (BaseOutline). A goal where the outline fits at no heading is moved to the
// nearest position where it fits, within goal_search_radius (reported), and given up with the
// reason when there is none. A system with explicit input
// (time, pose estimate), output (base velocity command) and state (goal, path, mode); the events it
// reports (goal reached, replans, recoveries, failures) go to the evaluation.
#include <Eigen/Core>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/common/pose2.h"
#include "trimbot/messages/commands.h"
#include "trimbot/stack/global_planner.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/stack/path_follower.h"

namespace trimbot::stack {

struct NavigatorParameters {
  PlannerParameters planner;
  FollowerParameters follower;
  double stop_clearance = 0.03;   // m: the outline this close to the costmap's obstacles -> stop
  double turn_check_angle = 0.3;  // rad: a turn on the spot is checked this far ahead
  double resume_clearance = 0.2;  // m: back off until this much is free again
  double backoff_speed = 0.1;     // m/s
  double max_backoff = 0.6;       // m
  double replan_deviation = 0.6;  // m off the path -> plan again
  int max_recoveries_per_goal = 5;
  int max_plan_failures = 3;        // per goal, then the goal is given up
  bool stop_on_failure = true;      // a goal given up ends the mission (false: on to the next goal)
  double goal_search_radius = 0.6;  // m: a goal where the outline fits nowhere moves at most this far
  double blocked_horizon = 4.0;     // m of path ahead checked when the costmap changes: where the
                                    // outline, driving it, comes within planner.min_clearance of a
                                    // seen obstacle, the path is blocked
};

struct NavigationEvent {
  enum class Type {
    kPlanned,
    kPlanFailed,
    kGoalReached,
    kGoalFailed,
    kObstacleStop,
    kRecovered,
    kPathBlocked,      // an obstacle seen on the path ahead: plan again
    kGoalAdjusted,     // the goal was in an obstacle's clearance: `position` is the goal used instead
    kApproachReached,  // a bush goal's approach point, reached by map: visual servoing starts
  };
  double stamp = 0.0;
  Type type = Type::kPlanned;
  int goal = 0;
  std::string detail;
  // kPlanned, kGoalReached: the goal planned to / arrived at (the asked one, or where it was
  // moved); kGoalAdjusted: where the goal was moved; kPathBlocked: the blocked point of the path.
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
};
const char* ToString(NavigationEvent::Type type);

// A goal of the navigator: a position, and the heading to arrive with when it matters (map frame,
// rad), else any.
struct NavigationGoal {
  NavigationGoal(const Eigen::Vector2d& point,
                 std::optional<double> heading = std::nullopt)  // NOLINT: a point is a goal
      : position(point), yaw(heading) {}
  Eigen::Vector2d position;
  std::optional<double> yaw;
};

class Navigator {
 public:
  enum class Mode { kIdle, kFollowing, kBackingOff, kDone, kFailed };

  // `outline`: the base's (RobotDescription::BaseOutline).
  Navigator(const OccupancyGrid& map, const BaseOutline& outline, const NavigatorParameters& parameters);
  // The planner refers to this navigator's costmap: not copied or moved.
  Navigator(const Navigator&) = delete;
  Navigator& operator=(const Navigator&) = delete;

  // Goals visited in order; events and current_goal() count them from `first_index` (the goals
  // may be a part of a longer mission).
  void SetGoals(const std::vector<NavigationGoal>& goals, int first_index = 0);
  // The prior map with what perception has seen added (same size, resolution and origin as the
  // prior map; std::invalid_argument otherwise). The path ahead is checked against it.
  void SetCostmap(OccupancyGrid costmap);
  messages::BaseVelocityCommand Update(double stamp, const Pose2& estimate);

  // Smallest distance from the outline at `pose` to an obstacle of the costmap (negative: overlap).
  // Clearances beyond `enough` may be reported as any value >= `enough`.
  double OutlineClearance(const Pose2& pose, double enough = std::numeric_limits<double>::infinity()) const {
    return planner_.Clearance(pose, enough);
  }
  // The planner on the costmap (its outline checks, standable positions).
  const GlobalPlanner& planner() const { return planner_; }

  Mode mode() const { return mode_; }
  int current_goal() const { return first_index_ + goal_; }
  const std::vector<Eigen::Vector2d>& path() const { return follower_.path(); }
  const OccupancyGrid& costmap() const { return costmap_; }
  // Events since the last call.
  std::vector<NavigationEvent> TakeEvents();
  // Wall-clock seconds spent in the global planner since construction.
  double planning_seconds() const { return planning_seconds_; }

 private:
  void PlanToCurrentGoal(double stamp, const Pose2& estimate);
  // Where the robot drives (by its estimate): appended to the trail it backs out along.
  void RecordTrail(const Pose2& estimate);
  // Drops the trail when the estimate has jumped away from it (a fix corrected it).
  void DropTrailIfJumped(const Pose2& estimate);
  // The pose a turn on the spot checks: `turn_left` (rad, signed) ahead, at most turn_check_angle.
  Pose2 TurnedAhead(const Pose2& estimate, double turn_left) const;
  // The back-off after an obstacle stop or a failed plan: the way it came, in reverse.
  messages::BaseVelocityCommand BackOff(double stamp, const Pose2& estimate);
  void GiveUpGoal(double stamp, const std::string& why);
  void Emit(double stamp, NavigationEvent::Type type, const std::string& detail = {},
            const Eigen::Vector2d& position = Eigen::Vector2d::Zero());
  // The first point of the path ahead where the outline, driving it, would come within the
  // planner's min_clearance of an obstacle perception added to the prior map; nullopt if none.
  std::optional<Eigen::Vector2d> PathAheadBlocked(const Pose2& estimate) const;
  // "at (x y), seen obstacle at (x y)": the blocked point and the nearest cell perception added.
  std::string DescribeBlock(const Eigen::Vector2d& blocked) const;

  const OccupancyGrid& map_;
  OccupancyGrid costmap_;  // the planner plans on this
  NavigatorParameters parameters_;
  GlobalPlanner planner_;
  PathFollower follower_;
  std::vector<NavigationGoal> goals_;
  int goal_ = 0;
  int first_index_ = 0;
  Mode mode_ = Mode::kIdle;
  int recoveries_ = 0;
  int plan_failures_ = 0;
  Pose2 backoff_start_;              // where the back-off started, and the heading it stopped with
  bool backoff_until_clear_ = true;  // an obstacle stop's back-off (a failed plan's: the whole max_backoff)
  std::deque<Pose2> trail_;          // the way the robot came, newest last (RecordTrail)
  std::vector<NavigationEvent> events_;
  double planning_seconds_ = 0.0;
  bool costmap_changed_ = false;
  Eigen::Vector2d active_goal_ = Eigen::Vector2d::Zero();  // the goal of the current plan
  std::vector<Eigen::Vector2d> goal_candidates_;           // where the outline fits near the goal
};

}  // namespace trimbot::stack
