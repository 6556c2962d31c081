#pragma once
// A goal of the stack's mission (RobotStack::SetGoals).
#include <Eigen/Core>
#include <optional>

#include "trimbot/perception/bush_estimator.h"

namespace trimbot::stack {

// A goal of the mission: a point to drive to, or a bush to approach for trimming (by map to an
// approach point, then by visual servoing until the arm's axis stands at the standoff).
struct Goal {
  Goal(const Eigen::Vector2d& point) : position(point) {}  // NOLINT(google-explicit-constructor): a point is a goal
  Goal(double x, double y) : position(x, y) {}
  // The bush as the survey knows it: its centre in the map and its shape (yaw in the map frame).
  static Goal ApproachBush(const Eigen::Vector2d& centre, const perception::BushShape& shape);
  // A bush to approach and then trim from the standoff (a topiary: the shape is its target).
  static Goal TrimBush(const Eigen::Vector2d& centre, const perception::BushShape& shape);
  // A bush to approach and scan only: its scan joins the bush's later trims' fits.
  static Goal ScanBush(const Eigen::Vector2d& centre, const perception::BushShape& shape);
  Eigen::Vector2d position;                   // the point, or the bush's surveyed centre
  std::optional<double> yaw;                  // a point goal's heading to arrive with (map frame, rad); unset: any
  std::optional<perception::BushShape> bush;  // set for a bush approach
  std::optional<double> side;                 // a bush approach's side: bearing from the bush's centre (map frame, rad)
  bool trim = false;                          // the bush is scanned once approached ...
  bool cut = false;                           // ... and trimmed
};

}  // namespace trimbot::stack
