#include "trimbot/stack/path_follower.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace trimbot::stack {
namespace {

// Closest point of segment [a, b] to p, as the fraction along it.
double Project(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  const Eigen::Vector2d ab = b - a;
  const double length2 = ab.squaredNorm();
  return length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
}

}  // namespace

bool PathFollower::Exact(std::size_t s) const {
  return s < clearance_.size() && clearance_[s] < parameters_.exact_below;
}

std::size_t PathFollower::StretchEnd(std::size_t segment) const {
  for (std::size_t v = segment + 1; v + 1 < path_.size(); ++v) {
    const Eigen::Vector2d in = path_[v] - path_[v - 1], out = path_[v + 1] - path_[v];
    const double turn = std::abs(std::atan2(in.x() * out.y() - in.y() * out.x(), in.dot(out)));
    if (turn > parameters_.sharp_turn) return v;
    if ((Exact(v - 1) || Exact(v)) && turn > parameters_.exact_align_tolerance) return v;
  }
  return path_.empty() ? 0 : path_.size() - 1;
}

bool PathFollower::Reached(std::size_t v, const Eigen::Vector2d& position) const {
  const double distance = (path_[v] - position).norm();
  if (!Exact(v - 1) && !Exact(v)) return distance < parameters_.vertex_tolerance;
  // Along the incoming segment: the turn on the spot there is what the plan checked.
  const Eigen::Vector2d in = path_[v] - path_[v - 1];
  const double to_go = in.norm() > 0.0 ? (path_[v] - position).dot(in) / in.norm() : 0.0;
  return distance < parameters_.vertex_tolerance && to_go < parameters_.exact_vertex_tolerance;
}

void PathFollower::SetPath(const std::vector<Eigen::Vector2d>& path, const std::vector<double>& clearance,
                           std::optional<double> final_yaw) {
  if (!clearance.empty() && clearance.size() + 1 != path.size()) {
    throw std::invalid_argument("PathFollower::SetPath: one clearance per segment of the path");
  }
  path_ = path;
  clearance_ = clearance;
  segment_ = 0;
  aligned_ = false;
  final_yaw_ = final_yaw;
  at_end_ = false;
}

Eigen::Vector2d PathFollower::LookaheadPoint(double fraction, std::size_t stretch_end) const {
  // Walk `lookahead` metres along the path from the closest point, not past the end of the stretch.
  if (path_.size() < 2) return path_[stretch_end];
  double remaining = parameters_.lookahead;
  Eigen::Vector2d from = path_[segment_] + fraction * (path_[segment_ + 1] - path_[segment_]);
  for (std::size_t s = segment_; s < stretch_end; ++s) {
    const double length = (path_[s + 1] - from).norm();
    if (length >= remaining) return from + remaining * (path_[s + 1] - from) / length;
    remaining -= length;
    from = path_[s + 1];
  }
  return path_[stretch_end];
}

FollowerOutput PathFollower::Update(const Pose2& pose) {
  FollowerOutput out;
  if (path_.empty()) {
    out.arrived = true;
    return out;
  }
  const Eigen::Vector2d position(pose.x, pose.y);
  const Eigen::Vector2d& goal = path_.back();
  out.distance_to_goal = (goal - position).norm();
  if (at_end_ || out.distance_to_goal < parameters_.goal_tolerance) {
    at_end_ = true;  // a turn on the spot does not leave the end
    const double turn = final_yaw_ ? WrapAngle(*final_yaw_ - pose.yaw) : 0.0;
    if (std::abs(turn) <= parameters_.exact_align_tolerance) {
      out.arrived = true;
      return out;
    }
    out.command.angular =
        std::clamp(parameters_.heading_gain * turn, -parameters_.max_angular_speed, parameters_.max_angular_speed);
    out.turn_left = turn;
    return out;
  }

  // A sharp vertex ends the current stretch: the robot drives to it and turns on the spot there
  // instead of cutting the corner (the planner checked the footprint along the segments only).
  std::size_t stretch_end = StretchEnd(segment_);
  while (stretch_end + 1 < path_.size() && Reached(stretch_end, position)) {
    segment_ = stretch_end;
    aligned_ = false;
    stretch_end = StretchEnd(segment_);
  }

  // Advance the progress segment to the closest one among the current and the next two.
  double best = std::numeric_limits<double>::infinity();
  std::size_t best_segment = segment_;
  double best_fraction = 0.0;
  for (std::size_t s = segment_; s < stretch_end && s < segment_ + 3; ++s) {
    const double f = Project(path_[s], path_[s + 1], position);
    const double d = (path_[s] + f * (path_[s + 1] - path_[s]) - position).norm();
    if (d < best) {
      best = d;
      best_segment = s;
      best_fraction = f;
    }
  }
  if (path_.size() == 1) best = out.distance_to_goal;
  segment_ = best_segment;
  out.deviation = best;

  const Eigen::Vector2d target = LookaheadPoint(best_fraction, stretch_end);
  const double distance_to_stop = (path_[stretch_end] - position).norm();

  // Target in base_link.
  const Eigen::Vector2d delta = target - position;
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  const double lx = c * delta.x() + s * delta.y();
  const double ly = -s * delta.x() + c * delta.y();
  const double heading_error = std::atan2(ly, lx);

  const double w_max = parameters_.max_angular_speed;
  const double align = Exact(segment_) ? parameters_.exact_align_tolerance : parameters_.align_tolerance;
  if (!aligned_ && std::abs(heading_error) <= align) aligned_ = true;
  if (!aligned_ || std::abs(heading_error) > parameters_.turn_in_place_above) {
    out.command.angular = std::clamp(parameters_.heading_gain * heading_error, -w_max, w_max);
    out.turn_left = heading_error;
    return out;
  }
  // Pure pursuit: the arc through the target has curvature 2 * ly / d^2.
  double speed = parameters_.cruise_speed;
  if (distance_to_stop < parameters_.slow_down_distance) {
    speed = std::max(parameters_.min_speed, speed * distance_to_stop / parameters_.slow_down_distance);
  }
  const double d2 = std::max(lx * lx + ly * ly, 1e-6);
  double curvature = 2.0 * ly / d2;
  // Keep within the turn rate limit by slowing down, not by leaving the arc.
  if (std::abs(speed * curvature) > w_max) speed = w_max / std::abs(curvature);
  out.command.linear = speed;
  out.command.angular = speed * curvature;
  return out;
}

}  // namespace trimbot::stack
