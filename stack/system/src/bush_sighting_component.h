#pragma once
// The bush of the current bush goal, looked for by stereo on the pair facing it (once it is in
// sighting range) and fitted with its surveyed shape: each frame's centre goes to the bush servo's
// track, and each frame is reported as a BushSighting.
#include <memory>
#include <optional>
#include <vector>

#include "ring_component.h"
#include "trimbot/perception/stereo.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/stack/goal.h"
#include "trimbot/stack/stack_parameters.h"

namespace trimbot::stack {

class BushSightingComponent : public RingComponent {
 public:
  explicit BushSightingComponent(const StackParameters& parameters) : parameters_(parameters) {}

  // Sets up the stereo for a mission with bush goals.
  void Prepare(const std::vector<Goal>& goals, const robot::CameraRig& rig);

  // There is a bush goal, its rate allows a frame at `stamp`, and a stereo pair faces the bush.
  bool Due(double stamp, const StackState& state) const override;
  messages::RingRequest Request(const StackState& state) const override;
  void Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) override;

  // The sightings since the last call.
  std::vector<BushSighting> TakeSightings();

 private:
  // The current bush goal's bush in base_link (map belief, or the track once there is one).
  Eigen::Vector2d ExpectedBushInBase(const StackState& state) const;
  // The stereo pair facing the current bush goal's bush, if one does and it is in sighting range.
  std::optional<int> PairFacingBush(const StackState& state) const;

  const StackParameters& parameters_;
  std::unique_ptr<perception::RingStereo> stereo_;  // made with a mission that has bush goals
  double next_frame_ = 0.0;
  std::vector<BushSighting> sightings_;  // since TakeSightings
};

}  // namespace trimbot::stack
