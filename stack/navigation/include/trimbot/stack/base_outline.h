#pragma once
// The base's outline on the ground - the rectangle in base_link that the URDF's collision geometry
// of the base and its wheels covers (robot::RobotDescription::BaseOutline) - and its clearance from
// the occupied cells of an occupancy grid, each cell taken as the square it is. The distance is
// exact (convex polygon to convex polygon), not the circles or inflation radius of a costmap: a
// 0.70 x 0.51 m base fits a 0.71 m gap only if it is checked as what it is.
//
// Cells outside the grid count as occupied (the robot does not know what is there).
#include <Eigen/Core>

#include "trimbot/common/pose2.h"
#include "trimbot/stack/occupancy_grid.h"

namespace trimbot::stack {

class BaseOutline {
 public:
  BaseOutline() = default;
  // Corners of the rectangle in base_link (min.x < max.x, min.y < max.y).
  BaseOutline(const Eigen::Vector2d& min, const Eigen::Vector2d& max);

  // Signed distance from the outline at `pose` (base_link in the map) to the nearest occupied cell:
  // positive when clear, negative when overlapping (then minus how deep the deepest overlapping
  // cell's centre lies inside). Clearances beyond `enough` may be reported as any value >= `enough`
  // (a cheap bound; callers that compare with a margin pass that margin).
  double Clearance(const OccupancyGrid& map, const Pose2& pose,
                   double enough = std::numeric_limits<double>::infinity()) const;

  // Smallest clearance while the base turns on the spot at `pose` to `to_yaw` the shorter way, the
  // outline checked every `step` metres of its farthest corner's travel (and the travel between
  // checks subtracted, so the result never overstates the clearance).
  double TurnClearance(const OccupancyGrid& map, const Pose2& pose, double to_yaw, double step,
                       double enough = std::numeric_limits<double>::infinity()) const;

  const Eigen::Vector2d& min() const { return min_; }
  const Eigen::Vector2d& max() const { return max_; }
  // Farthest point of the outline from base_link (what sweeps widest turning on the spot).
  double reach() const { return reach_; }
  double width() const { return max_.y() - min_.y(); }
  double length() const { return max_.x() - min_.x(); }

 private:
  Eigen::Vector2d min_ = Eigen::Vector2d::Zero(), max_ = Eigen::Vector2d::Zero();
  double reach_ = 0.0;
};

}  // namespace trimbot::stack
