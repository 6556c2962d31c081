#include "local_fusion_component.h"

#include <utility>

namespace trimbot::stack {

LocalFusionComponent::LocalFusionComponent(const perception::LocalFusionOptions& options, const robot::CameraRig& rig) {
  if (options.enabled) fusion_ = std::make_unique<perception::LocalFusion>(rig, options);
}

bool LocalFusionComponent::Due(double stamp, const StackState& /*state*/) const {
  return fusion_ != nullptr && fusion_->Wants(stamp);
}

messages::RingRequest LocalFusionComponent::Request(const StackState& state) const {
  messages::RingRequest stereo;
  for (int i = 0; i < state.rig.size(); ++i) stereo.cameras.push_back(i);
  stereo.resolution_scale = 1.0;  // stereo rectifies with the calibration's image size
  return stereo;
}

void LocalFusionComponent::Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) {
  ScopedTimer timer(&telemetry->timings.perception);
  // The odometry pose at the frame's stamp: wheel ticks up to the frame have been added.
  registration_ = fusion_->Add(frame, ToIsometry(state->odometry.pose()));
}

std::optional<perception::CloudRegistration> LocalFusionComponent::TakeRegistration() {
  std::optional<perception::CloudRegistration> taken = std::move(registration_);
  registration_.reset();
  return taken;
}

}  // namespace trimbot::stack
