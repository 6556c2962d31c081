#pragma once
// Global path planning with OMPL over the robot's costmap (the prior map and what perception has
// seen): RRT* in the plane for base_link, keeping `robot_radius` from every occupied cell, and
// along every path segment keeping the footprint - pointing along the segment, as the robot
// drives it - `footprint_margin` clear; then shortcut-simplified. The planner runs for a fixed
// number of iterations (not a time budget), so with OMPL's seed fixed (ompl::RNG::setSeed, once
// per process) the same problem gives the same path on any machine.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/stack/occupancy_grid.h"

namespace trimbot::stack {

// The base footprint as circles along base_link's x axis (rectangle 0.70 x 0.51 m from x = -0.12).
struct Footprint {
  std::vector<double> circle_x = {0.02, 0.23, 0.44};  // m in base_link
  double circle_radius = 0.27;                        // m

  // Smallest distance from the footprint at (x, y, yaw) to an obstacle of the map (negative:
  // overlap).
  double Clearance(const OccupancyGrid& map, double x, double y, double yaw) const;
};

struct PlannerParameters {
  Footprint footprint;
  double robot_radius = 0.5;           // m: clearance from base_link to the map's obstacles
  double footprint_margin = 0.1;       // m: clearance of the footprint driving along the path
  double start_footprint_free = 0.25;  // m: near the start only base_link's clearance is checked (the
                                       // robot turns on the spot there; the obstacle stop guards it)
  int iterations = 3000;               // RRT* iterations per plan
  double range = 1.5;                  // m: longest RRT* edge
  double start_escape_radius = 1.0;    // m: a start inside the clearance is moved out by up to this
};

struct PlanResult {
  bool found = false;
  std::vector<Eigen::Vector2d> path;  // map frame, from the start to the goal
  double length = 0.0;                // m
  std::string message;                // why no path was found
};

// Seeds OMPL's random numbers for this process. Call once, before the first plan (OMPL seeds each
// planner's generator from this seed in turn, so the sequence of plans is reproducible).
void SeedPlanner(std::uint64_t seed);

class GlobalPlanner {
 public:
  GlobalPlanner(const OccupancyGrid& map, const PlannerParameters& parameters);

  // `attempt` k > 0 (a retry after a failed plan) runs 2^k times the iterations: narrow approaches
  // to a goal among bushes may need a denser tree.
  PlanResult Plan(const Eigen::Vector2d& start, const Eigen::Vector2d& goal, int attempt = 0) const;
  // base_link may be at `point` (the clearance holds).
  bool Free(const Eigen::Vector2d& point) const;
  // The free point nearest to `point` within `radius`, or `point` itself if none is free.
  Eigen::Vector2d NearestFree(const Eigen::Vector2d& point, double radius) const;
  // Clearance at which the robot can arrive from any direction: the footprint's reach from
  // base_link plus footprint_margin (the footprint may face the obstacle on arrival).
  double ArrivalClearance() const;
  // The point nearest to `point` within `radius` that keeps `clearance` from every obstacle, or
  // nullopt if there is none.
  std::optional<Eigen::Vector2d> NearestWithClearance(const Eigen::Vector2d& point, double clearance,
                                                      double radius) const;

  const OccupancyGrid& map() const { return map_; }
  const PlannerParameters& parameters() const { return parameters_; }

 private:
  const OccupancyGrid& map_;
  PlannerParameters parameters_;
};

}  // namespace trimbot::stack
