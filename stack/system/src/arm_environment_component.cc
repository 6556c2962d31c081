#include "arm_environment_component.h"

#include <cmath>

#include "trimbot/perception/point_cloud.h"

namespace trimbot::stack {

void ArmEnvironmentComponent::Prepare(bool arm_goals, const robot::CameraRig& rig) {
  if (arm_goals && !stereo_) stereo_ = std::make_unique<perception::RingStereo>(rig, perception::StereoOptions{});
}

bool ArmEnvironmentComponent::Due(double /*stamp*/, const StackState& state) const {
  const bool arm = state.mission.has_arm_goals() && state.arm.WantsEnvironment() && state.mission.NavigationGoalsDone();
  const bool trim = state.mission.trimming() && state.trim.WantsPoints();
  return (arm || trim) && std::abs(state.last_linear_command) < 1e-9;
}

messages::RingRequest ArmEnvironmentComponent::Request(const StackState& state) const {
  return PairsRequest(state.rig.StereoPairs());
}

void ArmEnvironmentComponent::Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) {
  ScopedTimer timer(&telemetry->timings.arm);
  perception::PointCloud seen;
  for (std::size_t pair = 0; pair < stereo_->rectifiers().size(); ++pair) {
    if (!PairDelivered(frame, stereo_->rectifiers()[pair].pair())) continue;
    const perception::PointCloud cloud = stereo_->ComputePair(frame, static_cast<int>(pair)).cloud;
    for (std::size_t i = 0; i < cloud.size(); ++i) seen.Add(cloud.points[i], cloud.covariances[i]);
  }
  if (seen.empty()) return;  // no pair delivered: the next frame
  if (state->mission.trimming()) {
    state->trim.SetPerceivedPoints(seen.points, seen.covariances);
  } else {
    state->arm.SetPerceivedPoints(seen.points, seen.covariances);
  }
  ++telemetry->timings.arm_frames;
}

}  // namespace trimbot::stack
