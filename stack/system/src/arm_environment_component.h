#pragma once
// The arm's surroundings: once the arm waits for them, the navigation goals are done and the base
// stands, one ring frame's stereo on every pair becomes the environment the arm plans around; a
// trim's scan is the same, once the trim waits for it.
#include <memory>

#include "ring_component.h"
#include "trimbot/perception/stereo.h"
#include "trimbot/robot/camera_rig.h"

namespace trimbot::stack {

class ArmEnvironmentComponent : public RingComponent {
 public:
  // Sets up the stereo for a mission with arm or trim goals.
  void Prepare(bool arm_goals, const robot::CameraRig& rig);

  // The base stands, and the arm has goals and waits for its surroundings after the navigation
  // goals, or a trim waits for its scan (whatever the stamp).
  bool Due(double stamp, const StackState& state) const override;
  messages::RingRequest Request(const StackState& state) const override;
  void Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) override;

 private:
  std::unique_ptr<perception::RingStereo> stereo_;  // made with arm goals
};

}  // namespace trimbot::stack
