#include "bush_sighting_component.h"

#include <cmath>
#include <utility>

#include "mission.h"
#include "trimbot/common/pose2.h"
#include "trimbot/perception/bush_estimator.h"

namespace trimbot::stack {

void BushSightingComponent::Prepare(const std::vector<Goal>& goals, const robot::CameraRig& rig) {
  if (HasBushGoal(goals) && !stereo_) {
    stereo_ = std::make_unique<perception::RingStereo>(rig, perception::StereoOptions{});
  }
}

Eigen::Vector2d BushSightingComponent::ExpectedBushInBase(const StackState& state) const {
  const BushServo& servo = state.mission.servo();
  if (servo.tracking()) return IntoFrame(state.servo_odometry.pose(), servo.centre());
  return IntoFrame(state.ekf.Estimate().pose, state.mission.goal(state.mission.bush_goal()).position);
}

std::optional<int> BushSightingComponent::PairFacingBush(const StackState& state) const {
  if (state.mission.bush_goal() < 0 || !stereo_) return std::nullopt;
  const Eigen::Vector2d bush = ExpectedBushInBase(state);
  if ((bush - state.arm_axis).norm() > parameters_.bush_approach.sighting_range) return std::nullopt;
  std::optional<int> best;
  double best_angle = parameters_.bush_approach.max_bearing;
  const auto& rectifiers = stereo_->rectifiers();
  for (std::size_t i = 0; i < rectifiers.size(); ++i) {
    const Eigen::Isometry3d& T = rectifiers[i].T_base_rectified_left();
    const Eigen::Vector2d axis = T.linear().col(2).head<2>(), to_bush = bush - T.translation().head<2>();
    const double angle = std::abs(WrapAngle(std::atan2(to_bush.y(), to_bush.x()) - std::atan2(axis.y(), axis.x())));
    if (angle <= best_angle) {
      best_angle = angle;
      best = static_cast<int>(i);
    }
  }
  return best;
}

bool BushSightingComponent::Due(double stamp, const StackState& state) const {
  return state.mission.bush_goal() >= 0 && stamp + 1e-9 >= next_frame_ && PairFacingBush(state).has_value();
}

messages::RingRequest BushSightingComponent::Request(const StackState& state) const {
  return PairsRequest({stereo_->rectifiers()[static_cast<std::size_t>(*PairFacingBush(state))].pair()});
}

void BushSightingComponent::Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) {
  ScopedTimer timer(&telemetry->timings.bush);
  Mission& mission = state->mission;
  const int pair = *PairFacingBush(*state);
  if (!PairDelivered(frame, stereo_->rectifiers()[static_cast<std::size_t>(pair)].pair())) return;
  next_frame_ = frame.stamp + 1.0 / parameters_.bush_approach.rate_hz;
  ++telemetry->timings.bush_frames;
  BushSighting sighting;
  sighting.stamp = frame.stamp;
  sighting.goal = mission.bush_goal();
  const Goal& goal = mission.goal(mission.bush_goal());
  // Until there is a track: the map's belief through the pose estimate now (odometry's heading drifts in turns).
  if (!mission.servo().tracking()) mission.ExpectBush();
  const perception::PointCloud cloud = stereo_->ComputePair(frame, pair).cloud;
  const auto ground = perception::FitGroundPlane(cloud);
  perception::BushShape shape = *goal.bush;
  shape.yaw -= state->ekf.Estimate().pose.yaw;  // map -> base_link
  const auto estimate =
      perception::FitBush(cloud, ground.value_or(perception::GroundPlane{}), shape, ExpectedBushInBase(*state),
                          parameters_.bush_approach.fit, &sighting.failure);
  if (estimate) {
    sighting.found = true;
    sighting.centre_base = estimate->centre;
    sighting.scale = estimate->scale;
    sighting.points = estimate->points;
    const Eigen::Vector2d from_arm = estimate->centre - state->arm_axis;
    sighting.distance = from_arm.norm();
    sighting.bearing = std::atan2(from_arm.y(), from_arm.x());
    // The odometry pose at the frame: wheel ticks up to the frame have been added.
    sighting.tracked = mission.servo().AddMeasurement(frame.stamp, state->servo_odometry.pose(), estimate->centre);
    if (!sighting.tracked) sighting.failure = "too far from the track";
  } else {
    mission.servo().AddMiss(frame.stamp);
  }
  mission.CountSighting(sighting.tracked);
  sightings_.push_back(std::move(sighting));
}

std::vector<BushSighting> BushSightingComponent::TakeSightings() {
  std::vector<BushSighting> taken = std::move(sightings_);
  sightings_.clear();
  return taken;
}

}  // namespace trimbot::stack
