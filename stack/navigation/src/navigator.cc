#include "trimbot/stack/navigator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace trimbot::stack {

const char* ToString(NavigationEvent::Type type) {
  switch (type) {
    case NavigationEvent::Type::kPlanned:
      return "planned";
    case NavigationEvent::Type::kPlanFailed:
      return "plan_failed";
    case NavigationEvent::Type::kGoalReached:
      return "goal_reached";
    case NavigationEvent::Type::kGoalFailed:
      return "goal_failed";
    case NavigationEvent::Type::kObstacleStop:
      return "obstacle_stop";
    case NavigationEvent::Type::kRecovered:
      return "recovered";
    case NavigationEvent::Type::kPathBlocked:
      return "path_blocked";
    case NavigationEvent::Type::kGoalAdjusted:
      return "goal_adjusted";
    case NavigationEvent::Type::kApproachReached:
      return "approach_reached";
  }
  return "?";
}

namespace {

// A turn on the spot costs the planner what driving for the same time would.
PlannerParameters WithTurnCost(PlannerParameters planner, const FollowerParameters& follower) {
  planner.turn_cost = follower.cruise_speed / follower.max_angular_speed;
  return planner;
}

}  // namespace

Navigator::Navigator(const OccupancyGrid& map, const BaseOutline& outline, const NavigatorParameters& parameters)
    : map_(map),
      costmap_(map),
      parameters_(parameters),
      planner_(costmap_, outline, WithTurnCost(parameters.planner, parameters.follower)),
      follower_(parameters.follower) {}

void Navigator::SetCostmap(OccupancyGrid costmap) {
  if (costmap.occupied().size() != map_.occupied().size() || costmap.resolution() != map_.resolution() ||
      costmap.origin() != map_.origin()) {
    throw std::invalid_argument("Navigator::SetCostmap: the costmap must have the prior map's cells");
  }
  if (cv::countNonZero(costmap.occupied() != costmap_.occupied()) == 0) return;  // nothing new
  costmap_ = std::move(costmap);  // the planner refers to costmap_ itself
  costmap_changed_ = true;
}

std::optional<Eigen::Vector2d> Navigator::PathAheadBlocked(const Pose2& estimate) const {
  const std::vector<Eigen::Vector2d>& path = follower_.path();
  const std::size_t first = follower_.segment();
  if (first + 1 >= path.size()) return std::nullopt;
  // From the robot's projection onto the segment it drives, along the path for blocked_horizon.
  const Eigen::Vector2d robot(estimate.x, estimate.y);
  const Eigen::Vector2d a0 = path[first], b0 = path[first + 1];
  const double length0 = (b0 - a0).squaredNorm();
  const double along0 = length0 > 0.0 ? std::clamp((robot - a0).dot(b0 - a0) / length0, 0.0, 1.0) : 0.0;
  const double step = 0.5 * costmap_.resolution();
  const double wanted = parameters_.planner.min_clearance;
  double travelled = 0.0;
  Eigen::Vector2d from = a0 + along0 * (b0 - a0);
  for (std::size_t i = first + 1; i < path.size() && travelled <= parameters_.blocked_horizon; ++i) {
    const Eigen::Vector2d to = path[i];
    const double length = (to - from).norm();
    const double heading = std::atan2(to.y() - from.y(), to.x() - from.x());
    const int steps = std::max(1, static_cast<int>(std::ceil(length / step)));
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d q = from + (static_cast<double>(k) / steps) * (to - from);
      // Right around the robot the obstacle stop guards it; and only what perception added
      // counts: the plan already kept its clearance from the prior map.
      if ((q - robot).norm() < parameters_.planner.start_free_radius) continue;
      const Pose2 pose{q.x(), q.y(), heading};
      if (planner_.Clearance(pose, wanted) < wanted && planner_.outline().Clearance(map_, pose, wanted) >= wanted) {
        return q;
      }
    }
    travelled += length;
    from = to;
  }
  return std::nullopt;
}

void Navigator::SetGoals(const std::vector<NavigationGoal>& goals, int first_index) {
  goals_ = goals;
  goal_ = 0;
  first_index_ = first_index;
  recoveries_ = 0;
  plan_failures_ = 0;
  follower_.SetPath({});
  mode_ = goals_.empty() ? Mode::kDone : Mode::kIdle;
}

void Navigator::Emit(double stamp, NavigationEvent::Type type, const std::string& detail,
                     const Eigen::Vector2d& position) {
  events_.push_back({stamp, type, first_index_ + goal_, detail, position});
}

std::vector<NavigationEvent> Navigator::TakeEvents() {
  std::vector<NavigationEvent> out;
  out.swap(events_);
  return out;
}

void Navigator::GiveUpGoal(double stamp, const std::string& why) {
  Emit(stamp, NavigationEvent::Type::kGoalFailed, why);
  follower_.SetPath({});
  if (parameters_.stop_on_failure) {
    mode_ = Mode::kFailed;
    return;
  }
  ++goal_;
  recoveries_ = 0;
  plan_failures_ = 0;
  mode_ = goal_ < static_cast<int>(goals_.size()) ? Mode::kIdle : Mode::kDone;
}

void Navigator::PlanToCurrentGoal(double stamp, const Pose2& estimate) {
  const auto start = std::chrono::steady_clock::now();
  const Eigen::Vector2d asked = goals_[goal_].position;
  const std::optional<double> yaw = goals_[goal_].yaw;
  if (plan_failures_ == 0) {
    // Where the outline fits, nearest first (the goal itself if it fits there): each failed plan
    // tries the next, since a pose that fits may not be reachable (no room to turn into it).
    goal_candidates_ =
        planner_.StandablePositions(asked, parameters_.goal_search_radius, parameters_.max_plan_failures, yaw);
    if (goal_candidates_.empty()) {
      GiveUpGoal(stamp, "the base's outline fits nowhere within " + std::to_string(parameters_.goal_search_radius) +
                            " m of the goal (keeping " + std::to_string(parameters_.planner.min_clearance) +
                            " m from the obstacles)");
      return;
    }
  }
  const Eigen::Vector2d goal =
      goal_candidates_[std::min(static_cast<std::size_t>(plan_failures_), goal_candidates_.size() - 1)];
  if (goal != asked) {
    Emit(stamp, NavigationEvent::Type::kGoalAdjusted, std::to_string((goal - asked).norm()) + " m", goal);
  }
  // To the goal's position within half a cell, at its heading if it has one.
  const PlanResult plan = planner_.Plan(estimate, goal, 0.5 * costmap_.resolution(), plan_failures_, yaw);
  active_goal_ = goal;
  planning_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!plan.found) {
    Emit(stamp, NavigationEvent::Type::kPlanFailed, plan.message);
    if (++plan_failures_ >= parameters_.max_plan_failures) {
      GiveUpGoal(stamp, "no path: " + plan.message);
    } else {
      // Boxed in (no room to turn, and the drive plans forward motions only): back out the way it
      // came before the next try, the whole max_backoff (the outline is clear: room is missing).
      backoff_start_ = {estimate.x, estimate.y, estimate.yaw};
      backoff_until_clear_ = false;
      mode_ = Mode::kBackingOff;
    }
    return;
  }
  follower_.SetPath(plan.path, plan.clearance, yaw);
  mode_ = Mode::kFollowing;
  Emit(stamp, NavigationEvent::Type::kPlanned, std::to_string(plan.length) + " m", active_goal_);
}

std::string Navigator::DescribeBlock(const Eigen::Vector2d& blocked) const {
  // The seen obstacle cell nearest to the blocked point, for the log.
  const cv::Point centre = costmap_.Cell(blocked);
  const int reach = static_cast<int>(std::ceil(planner_.outline().reach() / costmap_.resolution())) + 1;
  double nearest = std::numeric_limits<double>::infinity();
  Eigen::Vector2d seen = blocked;
  for (int dr = -reach; dr <= reach; ++dr) {
    for (int dc = -reach; dc <= reach; ++dc) {
      const cv::Point cell(centre.x + dc, centre.y + dr);
      if (cell.x < 0 || cell.y < 0 || cell.x >= costmap_.occupied().cols || cell.y >= costmap_.occupied().rows)
        continue;
      if (costmap_.occupied().at<std::uint8_t>(cell) == 0 || map_.occupied().at<std::uint8_t>(cell) != 0) continue;
      const Eigen::Vector2d p = costmap_.CellCentre(cell);
      if ((p - blocked).norm() < nearest) {
        nearest = (p - blocked).norm();
        seen = p;
      }
    }
  }
  std::ostringstream where;
  where << std::fixed << std::setprecision(2) << "at (" << blocked.x() << " " << blocked.y() << "), seen obstacle at ("
        << seen.x() << " " << seen.y() << ")";
  return where.str();
}

namespace {

// The trail: a pose each kTrailStep driven or kTrailTurn turned, the last kTrailPoses of them.
constexpr double kTrailStep = 0.05;       // m
constexpr double kTrailTurn = 0.1;        // rad
constexpr std::size_t kTrailPoses = 200;  // >= 10 m of driving
// A trail position counts as undone within half a step.
constexpr double kTrailReached = 0.5 * kTrailStep;
// The estimate this far from the trail's newest pose has jumped (a fix corrected it): the trail,
// in the old estimate's frame, no longer says where the robot came from.
constexpr double kTrailJump = 3.0 * kTrailStep;

}  // namespace

void Navigator::DropTrailIfJumped(const Pose2& estimate) {
  if (!trail_.empty() && std::hypot(estimate.x - trail_.back().x, estimate.y - trail_.back().y) > kTrailJump) {
    trail_.clear();
  }
}

Pose2 Navigator::TurnedAhead(const Pose2& estimate, double turn_left) const {
  return {estimate.x, estimate.y,
          estimate.yaw + std::copysign(std::min(parameters_.turn_check_angle, std::abs(turn_left)), turn_left)};
}

void Navigator::RecordTrail(const Pose2& estimate) {
  DropTrailIfJumped(estimate);
  if (!trail_.empty()) {
    const Pose2& last = trail_.back();
    if (std::hypot(estimate.x - last.x, estimate.y - last.y) < kTrailStep &&
        std::abs(WrapAngle(estimate.yaw - last.yaw)) < kTrailTurn) {
      return;
    }
  }
  trail_.push_back(estimate);
  if (trail_.size() > kTrailPoses) trail_.pop_front();
}

messages::BaseVelocityCommand Navigator::BackOff(double stamp, const Pose2& estimate) {
  // Back until the outline, at the heading it stopped with, is clear again (after an obstacle
  // stop) or the back-off distance is used up, or until the outline a few centimetres further
  // back would come within stop_clearance of what is behind (reversing is checked like driving
  // forward).
  messages::BaseVelocityCommand command;
  const double moved = std::hypot(estimate.x - backoff_start_.x, estimate.y - backoff_start_.y);
  constexpr double kLookBehind = 0.05;  // m: a little more than one update's travel backwards
  const Pose2 behind{estimate.x - kLookBehind * std::cos(estimate.yaw),
                     estimate.y - kLookBehind * std::sin(estimate.yaw), estimate.yaw};
  const double here = OutlineClearance({estimate.x, estimate.y, backoff_start_.yaw}, parameters_.resume_clearance);
  const double there = OutlineClearance(behind, parameters_.resume_clearance);
  // After a failed plan the way it came is backed the whole max_backoff, but straight back (blind
  // to where it leads) only until clear.
  const bool until_clear = backoff_until_clear_ || trail_.empty();
  if ((until_clear && here >= parameters_.resume_clearance) || moved >= parameters_.max_backoff ||
      (there < parameters_.stop_clearance && there < OutlineClearance(estimate) - 1e-3)) {
    Emit(stamp, NavigationEvent::Type::kRecovered, std::to_string(moved) + " m back");
    mode_ = Mode::kIdle;
    return command;  // plan on the next update, from where the robot stopped
  }
  // The way it came, undone newest first: reversing to each trail position in turn, turning back
  // (on the spot) where the way turned, so the outline sweeps only what it swept coming in. A
  // position reached or passed (ahead of the robot reversing) is done. With no trail left, or a
  // turn back that would come within stop_clearance (the trail no longer fits the estimate):
  // straight back.
  const Eigen::Vector2d heading(std::cos(estimate.yaw), std::sin(estimate.yaw));
  DropTrailIfJumped(estimate);
  while (!trail_.empty()) {
    const Eigen::Vector2d to(trail_.back().x - estimate.x, trail_.back().y - estimate.y);
    if (to.norm() >= kTrailReached && to.dot(heading) <= 0.0) break;
    trail_.pop_back();
  }
  if (!trail_.empty()) {
    const Eigen::Vector2d away(estimate.x - trail_.back().x, estimate.y - trail_.back().y);
    const double error = WrapAngle(std::atan2(away.y(), away.x()) - estimate.yaw);
    const FollowerParameters& follower = parameters_.follower;
    const bool aligned = std::abs(error) < follower.align_tolerance;
    if (aligned ||
        OutlineClearance(TurnedAhead(estimate, error), parameters_.stop_clearance) >= parameters_.stop_clearance) {
      command.angular =
          std::clamp(follower.heading_gain * error, -follower.max_angular_speed, follower.max_angular_speed);
      if (aligned) command.linear = -parameters_.backoff_speed;
      return command;
    }
    trail_.clear();
  }
  command.linear = -parameters_.backoff_speed;
  return command;
}

messages::BaseVelocityCommand Navigator::Update(double stamp, const Pose2& estimate) {
  messages::BaseVelocityCommand stop;
  if (mode_ == Mode::kDone || mode_ == Mode::kFailed) return stop;

  if (mode_ == Mode::kIdle) {
    PlanToCurrentGoal(stamp, estimate);
    if (mode_ != Mode::kFollowing) return stop;
  }

  if (mode_ == Mode::kBackingOff) return BackOff(stamp, estimate);
  RecordTrail(estimate);

  // Following.
  const FollowerOutput follow = follower_.Update(estimate);
  if (follow.arrived) {
    Emit(stamp, NavigationEvent::Type::kGoalReached, {}, active_goal_);
    ++goal_;
    recoveries_ = 0;
    plan_failures_ = 0;
    follower_.SetPath({});
    mode_ = goal_ < static_cast<int>(goals_.size()) ? Mode::kIdle : Mode::kDone;
    return stop;
  }
  // Too close to an obstacle while moving towards it - driving forward, or turning on the spot,
  // which sweeps the outline's front round (checked turn_check_angle ahead, or where the turn
  // ends if sooner: a small turn lining up in a narrow passage must not be stopped for what a
  // bigger one would hit): stop and back off.
  const bool turning_in_place = follow.command.linear == 0.0 && follow.command.angular != 0.0;
  const Pose2 turned = TurnedAhead(estimate, follow.turn_left);
  const bool too_close =
      (follow.command.linear > 0.0 &&
       OutlineClearance(estimate, parameters_.stop_clearance) < parameters_.stop_clearance) ||
      (turning_in_place && OutlineClearance(turned, parameters_.stop_clearance) < parameters_.stop_clearance);
  if (too_close) {
    Emit(stamp, NavigationEvent::Type::kObstacleStop, turning_in_place ? "turning" : "driving");
    if (++recoveries_ > parameters_.max_recoveries_per_goal) {
      GiveUpGoal(stamp, "too many recoveries");
      return stop;
    }
    backoff_start_ = {estimate.x, estimate.y, estimate.yaw};
    backoff_until_clear_ = true;
    mode_ = Mode::kBackingOff;
    return stop;
  }
  if (costmap_changed_) {
    costmap_changed_ = false;
    if (const auto blocked = PathAheadBlocked(estimate)) {
      Emit(stamp, NavigationEvent::Type::kPathBlocked, DescribeBlock(*blocked), *blocked);
      mode_ = Mode::kIdle;
      return stop;
    }
  }
  if (follow.deviation > parameters_.replan_deviation) {
    mode_ = Mode::kIdle;
    return stop;
  }
  return follow.command;
}

}  // namespace trimbot::stack
