#pragma once
// Path following for the differential-drive base: pure pursuit on a polyline at a cruise speed
// (the real robot drove at ~25 cm/s). On a new path it first turns on the spot to face along it
// (driving off on an arc would swing the front of the base, 0.7 m ahead of the axle, into the bush
// it just reached); later it turns on the spot when the path points far away, and slows down for
// the goal. At sharp corners of the path it stops and turns on the spot rather than cutting them.
// Where the plan passes close to obstacles (its clearance per segment below `exact_below`) it drives
// the plan's own motions - to each vertex, turn on the spot, straight on - lined up tightly.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "trimbot/common/pose2.h"
#include "trimbot/messages/commands.h"

namespace trimbot::stack {

struct FollowerParameters {
  double cruise_speed = 0.25;        // m/s
  double lookahead = 0.6;            // m along the path
  double max_angular_speed = 0.6;    // rad/s
  double align_tolerance = 0.15;     // rad: on a new path, turn on the spot until within this
  double turn_in_place_above = 0.6;  // rad: heading errors above this turn on the spot first
  double heading_gain = 1.5;         // 1/s, for turning on the spot
  double sharp_turn = 0.5;           // rad: path vertices turning more are driven to, not cut
  double vertex_tolerance = 0.06;    // m: a sharp vertex counts as reached within this
  double goal_tolerance = 0.08;      // m: arrival, judged on the pose estimate
  double slow_down_distance = 0.6;   // m before the goal
  double min_speed = 0.05;           // m/s near the goal
  // Segments the plan keeps closer than `exact_below` to obstacles are driven as planned: stopped
  // at within `exact_vertex_tolerance` (along the segment) and set off on lined up within
  // `exact_align_tolerance`. The follower's slack elsewhere would use such a clearance up: 0.15 rad
  // of alignment at the outline's corners 0.41 m out is 6 cm, and pure pursuit cutting a 0.5 rad
  // corner with a 0.6 m lookahead leaves the path by about 8 cm.
  double exact_below = 0.15;             // m
  double exact_align_tolerance = 0.02;   // rad
  double exact_vertex_tolerance = 0.01;  // m
};

struct FollowerOutput {
  messages::BaseVelocityCommand command;
  bool arrived = false;
  double distance_to_goal = 0.0;  // m, straight line from the estimate
  double deviation = 0.0;         // m, from the estimate to the nearest point of the path
  double turn_left = 0.0;         // rad (signed) still to turn, when turning on the spot
};

class PathFollower {
 public:
  explicit PathFollower(const FollowerParameters& parameters) : parameters_(parameters) {}

  // `clearance`: per segment (path[i] to path[i + 1]) the outline's clearance the plan keeps along
  // it (PlanResult::clearance); empty: room everywhere. `final_yaw`: the heading to arrive with
  // (a turn on the spot at the end, to within exact_align_tolerance), else any.
  void SetPath(const std::vector<Eigen::Vector2d>& path, const std::vector<double>& clearance = {},
               std::optional<double> final_yaw = std::nullopt);
  FollowerOutput Update(const Pose2& pose);
  const std::vector<Eigen::Vector2d>& path() const { return path_; }
  std::size_t segment() const { return segment_; }  // being driven: path()[segment] to path()[segment + 1]
  const FollowerParameters& parameters() const { return parameters_; }

 private:
  FollowerParameters parameters_;
  std::vector<Eigen::Vector2d> path_;
  std::vector<double> clearance_;  // per segment, or empty
  std::size_t segment_ = 0;        // progress along the path: never goes back, so loops are not cut
  bool aligned_ = false;           // has faced along the path since it was set (or since a sharp vertex)
  std::optional<double> final_yaw_;
  bool at_end_ = false;  // within goal_tolerance of the end: only the turn to final_yaw is left

  // Whether segment `s` is driven exactly (its clearance below exact_below).
  bool Exact(std::size_t s) const;
  // Index of the first vertex after `segment` to stop and turn at (or of the goal): a sharp one, or
  // one turning more than exact_align_tolerance next to an exact segment.
  std::size_t StretchEnd(std::size_t segment) const;
  // Whether the robot at `position` has reached vertex `v`, where a stretch ends.
  bool Reached(std::size_t v, const Eigen::Vector2d& position) const;
  // The pure-pursuit target: `lookahead` along the path from `fraction` of the progress segment.
  Eigen::Vector2d LookaheadPoint(double fraction, std::size_t stretch_end) const;
};

}  // namespace trimbot::stack
