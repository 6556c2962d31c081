#include "trimbot/stack/bush_servo.h"

#include <algorithm>
#include <cmath>

#include "trimbot/common/pose2.h"

namespace trimbot::stack {
namespace {

// |value| clamped to [low, high], with value's sign; 0 stays 0.
double Saturate(double value, double low, double high) {
  if (value == 0.0) return 0.0;
  return std::copysign(std::clamp(std::abs(value), low, high), value);
}

}  // namespace

const char* ToString(BushServo::Mode mode) {
  switch (mode) {
    case BushServo::Mode::kIdle:
      return "idle";
    case BushServo::Mode::kServoing:
      return "servoing";
    case BushServo::Mode::kSettling:
      return "settling";
    case BushServo::Mode::kDone:
      return "done";
    case BushServo::Mode::kFailed:
      return "failed";
  }
  return "?";
}

BushServo::BushServo(const BushServoParameters& parameters, const Eigen::Vector2d& arm_axis)
    : parameters_(parameters), arm_axis_(arm_axis) {}

void BushServo::Expect(const Eigen::Vector2d& expected_centre, double outline_radius) {
  if (tracking() && (centre() - expected_centre).norm() > parameters_.max_jump + outline_radius) {
    weighted_sum_.setZero();  // what was tracked was something else
    weight_ = 0.0;
    candidate_.reset();
  }
  expected_ = expected_centre;
  target_distance_ = outline_radius + parameters_.surface_gap;
}

void BushServo::Start(double stamp) {
  mode_ = Mode::kServoing;
  failure_.clear();
  start_ = stamp;
  settle_count_ = 0;
  lost_ = 0;
  stopped_since_ = -1.0;
}

Eigen::Vector2d BushServo::DistanceBearing(const Pose2& odometry) const {
  const Eigen::Vector2d from_arm = IntoFrame(odometry, centre()) - arm_axis_;
  return {from_arm.norm(), std::atan2(from_arm.y(), from_arm.x())};
}

bool BushServo::AddMeasurement(double stamp, const Pose2& odometry, const Eigen::Vector2d& centre_base) {
  Eigen::Vector2d centre = FromFrame(odometry, centre_base);
  // The first measurement is gated by the map's belief, which may be off by the map's and the
  // pose estimate's errors; later ones by the track.
  const double gate = parameters_.max_jump + (tracking() ? 0.0 : parameters_.first_gate_margin);
  if ((centre - this->centre()).norm() > gate) {
    // Only near the map's belief: a neighbour seen twice (the bush hidden behind it) must not take
    // the track away.
    const bool confirmed = candidate_ && (centre - *candidate_).norm() <= parameters_.max_jump &&
                           (centre - expected_).norm() <= parameters_.max_jump + parameters_.first_gate_margin;
    if (!confirmed) {
      candidate_ = centre;
      AddMiss(stamp);
      return false;
    }
    weighted_sum_.setZero();  // two frames agree on another place: start again from them
    weight_ = 0.0;
    centre = 0.5 * (centre + *candidate_);
  }
  candidate_.reset();
  // Weighted by the inverse variance: stereo's depth error grows with the square of the range.
  const double range = (centre_base - arm_axis_).norm();
  const double sigma = parameters_.range_sigma * range * range;
  const double weight = 1.0 / (sigma * sigma);
  weighted_sum_ = parameters_.memory * weighted_sum_ + weight * centre;
  weight_ = parameters_.memory * weight_ + weight;
  lost_ = 0;
  if (mode_ == Mode::kSettling && stopped_since_ >= 0.0 && stamp >= stopped_since_ + parameters_.settle_time) {
    ++settle_count_;
  }
  return true;
}

void BushServo::AddMiss(double /*stamp*/) {
  if (mode_ != Mode::kServoing && mode_ != Mode::kSettling) return;
  if (++lost_ > parameters_.max_lost_frames) {
    mode_ = Mode::kFailed;
    failure_ = "bush lost: no usable centre in " + std::to_string(lost_) + " frames";
  }
}

messages::BaseVelocityCommand BushServo::Update(double stamp, const Pose2& odometry) {
  if (mode_ != Mode::kServoing && mode_ != Mode::kSettling) return {};
  if (stamp - start_ > parameters_.timeout) {
    mode_ = Mode::kFailed;
    failure_ = "servo timed out after " + std::to_string(parameters_.timeout) + " s";
    return {};
  }
  if (!tracking()) return {};  // stand and look until the bush is seen
  const Eigen::Vector2d db = DistanceBearing(odometry);
  const double distance_error = db.x() - target_distance_;
  const double bearing_error = WrapAngle(db.y() - parameters_.bearing);
  const bool arrived = std::abs(distance_error) <= parameters_.distance_tolerance &&
                       std::abs(bearing_error) <= parameters_.bearing_tolerance;
  if (arrived) {
    if (mode_ == Mode::kServoing) {
      mode_ = Mode::kSettling;
      stopped_since_ = stamp;
      settle_count_ = 0;
    } else if (settle_count_ >= parameters_.settle_frames) {
      mode_ = Mode::kDone;  // still there after the frames taken standing still
    }
    return {};
  }
  mode_ = Mode::kServoing;
  stopped_since_ = -1.0;
  messages::BaseVelocityCommand command;
  const double turn =
      Saturate(parameters_.turn_gain * bearing_error, parameters_.min_turn_rate, parameters_.max_turn_rate);
  // Turn on the spot first when the bush is well off the bearing, then drive and steer.
  command.angular = std::abs(bearing_error) > parameters_.bearing_tolerance ? turn : 0.0;
  if (std::abs(bearing_error) <= parameters_.turn_first && std::abs(distance_error) > parameters_.distance_tolerance) {
    command.linear = Saturate(parameters_.gain * distance_error, parameters_.min_speed, parameters_.max_speed);
  }
  return command;
}

}  // namespace trimbot::stack
