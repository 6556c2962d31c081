#pragma once
// Local fusion (perception::LocalFusion) as a ring component: the whole ring's stereo cloud every
// interval, registered to the previous one from the wheel odometry's guess.
#include <memory>
#include <optional>

#include "ring_component.h"
#include "trimbot/perception/local_fusion.h"
#include "trimbot/robot/camera_rig.h"

namespace trimbot::stack {

class LocalFusionComponent : public RingComponent {
 public:
  LocalFusionComponent(const perception::LocalFusionOptions& options, const robot::CameraRig& rig);

  // Local fusion is configured and wants a frame at `stamp`.
  bool Due(double stamp, const StackState& state) const override;
  messages::RingRequest Request(const StackState& state) const override;
  void Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) override;

  // The registration of the last frame since the last call, if it gave one.
  std::optional<perception::CloudRegistration> TakeRegistration();

 private:
  std::unique_ptr<perception::LocalFusion> fusion_;  // when enabled
  std::optional<perception::CloudRegistration> registration_;
};

}  // namespace trimbot::stack
