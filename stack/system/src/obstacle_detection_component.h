#pragma once
// Obstacles seen by stereo: the pairs facing the direction of travel, turned into obstacle and
// ground points, integrated into the obstacle layer over the prior map, whose merge becomes the
// navigator's costmap.
#include <memory>
#include <vector>

#include "ring_component.h"
#include "trimbot/perception/stereo.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/stack/obstacle_layer.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/stack/stack_parameters.h"

namespace trimbot::stack {

class ObstacleDetectionComponent : public RingComponent {
 public:
  ObstacleDetectionComponent(const StackParameters& parameters, const robot::CameraRig& rig);

  bool enabled() const { return stereo_ != nullptr; }
  // A new prior map: a new obstacle layer over it.
  void SetMap(const OccupancyGrid& map);
  // The stereo pairs (indices into the rig's pairs) facing the direction of travel, which the sign
  // of `linear_command` gives.
  std::vector<int> PairsAhead(double linear_command) const;

  // Obstacle detection is configured, has a map, and its rate allows a frame at `stamp`.
  bool Due(double stamp, const StackState& state) const override;
  messages::RingRequest Request(const StackState& state) const override;
  void Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) override;

 private:
  const StackParameters& parameters_;
  std::unique_ptr<perception::RingStereo> stereo_;  // with obstacle detection on
  std::unique_ptr<ObstacleLayer> layer_;            // made with the map
  double next_frame_ = 0.0;
};

}  // namespace trimbot::stack
