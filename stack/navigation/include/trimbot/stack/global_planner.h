#pragma once
// Global path planning with OMPL over the robot's costmap (the prior map and what perception has
// seen), in SE(2) with the base's real outline (BaseOutline: the URDF's collision rectangle, exact
// against the costmap's cells):
// - states (x, y, yaw); a motion between two states is what the differential drive follows
//   exactly: turn on the spot to face the second state, drive straight to it, turn on the spot to
//   its heading. The outline is checked at every pose along it (straight: every half cell; turning:
//   every half cell of its farthest corner's travel);
// - the outline must keep `min_clearance` from every occupied cell (the wall); below
//   `preferred_clearance` each metre driven costs up to `clearance_cost` metres more (clearance as
//   a cost: a narrow passage is allowed, a wide one preferred); turning on the spot costs the
//   driving the same time would (`turn_cost`, from the follower's speeds);
// - a goal is a position with a tolerance and any heading (OMPL samples goal poses at the headings
//   where the outline fits);
// - RRT* for a fixed number of iterations (not a time budget), then shortcut-simplified: with OMPL's
//   seed fixed (SeedPlanner, once per process) the same problem gives the same path on any machine.
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/common/pose2.h"
#include "trimbot/stack/base_outline.h"
#include "trimbot/stack/occupancy_grid.h"

namespace trimbot::stack {

struct PlannerParameters {
  double min_clearance = 0.05;       // m: the outline's clearance from every occupied cell
  double preferred_clearance = 0.4;  // m: less than this costs extra ...
  double clearance_cost = 2.0;       // ... up to this many metres per metre driven at no clearance
  double turn_cost = 0.4;            // m per rad turned on the spot (set from the follower's speeds)
  double start_free_radius = 0.25;   // m: near the start the outline need only get no closer to an
                                     // obstacle than it starts (after a stop it may be within min_clearance)
  double start_escape_radius = 1.0;  // m: a start whose outline overlaps is moved out by up to this
  int iterations = 3000;             // RRT* iterations per plan
  double range = 1.5;                // m: longest RRT* edge
};

struct PlanResult {
  bool found = false;
  std::vector<Eigen::Vector2d> path;  // map frame, from the start to the goal
  // Per segment (path[i] to path[i + 1]): the outline's smallest clearance driving along it, at
  // most preferred_clearance (what the follower needs to know: where to drive exactly as planned).
  std::vector<double> clearance;
  double length = 0.0;  // m
  double cost = 0.0;    // m: length plus the turns' and the clearance's costs
  std::string message;  // why no path was found
};

// Seeds OMPL's random numbers for this process. Call once, before the first plan (OMPL seeds each
// planner's generator from this seed in turn, so the sequence of plans is reproducible).
void SeedPlanner(std::uint64_t seed);

class GlobalPlanner {
 public:
  GlobalPlanner(const OccupancyGrid& map, const BaseOutline& outline, const PlannerParameters& parameters);

  // A path from `start` to a pose whose position is within `tolerance` of `goal`, at heading `yaw`
  // if given (the path ends with the turn on the spot to it, checked like every turn), else any.
  // `attempt` k > 0 (a retry after a failed plan) runs 2^k times the iterations.
  PlanResult Plan(const Pose2& start, const Eigen::Vector2d& goal, double tolerance, int attempt = 0,
                  std::optional<double> yaw = std::nullopt) const;

  // The outline's clearance at `pose` (BaseOutline::Clearance on the map).
  double Clearance(const Pose2& pose, double enough = std::numeric_limits<double>::infinity()) const;
  // The outline at `pose` keeps min_clearance.
  bool Valid(const Pose2& pose) const;
  // Of 32 headings at `position`, the one with the most clearance if it keeps min_clearance.
  std::optional<double> FreeHeading(const Eigen::Vector2d& position) const;
  // Up to `count` positions within `radius` of `point` that the drive can enter going forwards
  // (some heading keeps min_clearance there and either turns round there or has a straight run of
  // a base length behind it), nearest first (rings a cell apart, points about a cell apart on each;
  // `point` itself first if it qualifies). Such a position may still be unreachable from the start
  // (the run behind it may lead nowhere): the navigator tries them in turn. With `yaw`, only that
  // heading counts.
  std::vector<Eigen::Vector2d> StandablePositions(const Eigen::Vector2d& point, double radius, int count,
                                                  std::optional<double> yaw = std::nullopt) const;
  // The cost of the motion a -> b (turn, straight, turn), in metres.
  double MotionCost(const Pose2& a, const Pose2& b) const;

  const OccupancyGrid& map() const { return map_; }
  const BaseOutline& outline() const { return outline_; }
  const PlannerParameters& parameters() const { return parameters_; }

 private:
  const OccupancyGrid& map_;
  BaseOutline outline_;
  PlannerParameters parameters_;
};

}  // namespace trimbot::stack
