#pragma once
// A component that runs on the camera ring's frames, as RobotStack schedules it - in the manner of
// Drake's periodic events: for a frame exposed at a stamp the stack asks each component whether it
// is due (RingRequestAt merges what the due ones use, so a driver delivers only that), then hands
// the frame to each component that is due (Add). Whether a component is due is decided in one
// place, Due; Wants and the scheduler are built on it.
#include <algorithm>
#include <vector>

#include "scoped_timer.h"
#include "stack_state.h"
#include "trimbot/messages/commands.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/stack/telemetry.h"

namespace trimbot::stack {

class RingComponent {
 public:
  virtual ~RingComponent() = default;

  // Whether the component uses a ring frame exposed at `stamp`, given the rest of the stack now.
  virtual bool Due(double stamp, const StackState& state) const = 0;
  // The cameras and resolution it uses of a frame it is due for.
  virtual messages::RingRequest Request(const StackState& state) const = 0;
  // Runs on a frame it is due for, feeding `state` (costmap, servo, arm) and counting in `telemetry`.
  virtual void Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) = 0;

  // What the component would use of a frame exposed at `stamp` (empty: it is not due).
  messages::RingRequest Wants(double stamp, const StackState& state) const {
    return Due(stamp, state) ? Request(state) : messages::RingRequest{};
  }
};

// The frame holds both images of the pair (a driver delivers only what was asked for, and cameras
// drop out).
inline bool PairDelivered(const messages::RingFrame& frame, const robot::StereoPair& pair) {
  const auto delivered = [&frame](int camera) {
    return std::any_of(frame.images.begin(), frame.images.end(),
                       [camera](const messages::Image& image) { return image.camera_index == camera; });
  };
  return delivered(pair.left) && delivered(pair.right);
}

// The cameras of stereo pairs, at the resolution stereo rectifies with (the calibration's).
inline messages::RingRequest PairsRequest(const std::vector<robot::StereoPair>& pairs) {
  messages::RingRequest request;
  for (const robot::StereoPair& pair : pairs) {
    request.cameras.push_back(pair.left);
    request.cameras.push_back(pair.right);
  }
  std::sort(request.cameras.begin(), request.cameras.end());
  request.resolution_scale = 1.0;
  return request;
}

}  // namespace trimbot::stack
