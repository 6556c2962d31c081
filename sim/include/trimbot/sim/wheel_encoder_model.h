#pragma once
// Wheel encoders: quantized counts of wheel rotation, with slip. MuJoCo's Coulomb contact does
// not produce the small continuous slip of a tyre on grass, so slip is applied here: while a
// wheel is on the ground it turns (1 + s) times as far as its contact point travels, with s from
// the surface's Gauss-Markov slip model. Odometry from these counts therefore over-estimates the
// distance travelled, as on the real lawn.
#include <cstdint>
#include <random>

#include "trimbot/common/random.h"
#include "trimbot/garden/object_class.h"
#include "trimbot/messages/sensor_messages.h"

namespace trimbot::sim {

class WheelEncoderModel {
 public:
  WheelEncoderModel(int ticks_per_revolution, std::uint64_t seed);

  // Advances by the true rotation of each wheel (rad) over dt; `surface` is the ground under the
  // wheel or nullptr when the wheel touches nothing.
  void Advance(double dt, double rotation_left, double rotation_right, const garden::SlipModel* surface_left,
               const garden::SlipModel* surface_right);
  messages::WheelTicks Read(double stamp) const;
  // Fault: extra slip per wheel for a while (a muddy patch), as a fraction of the travel.
  void SetExtraSlip(double left, double right) {
    left_.extra_slip = left;
    right_.extra_slip = right;
  }

 private:
  struct Wheel {
    double measured_angle = 0.0;  // rad, what the encoder has seen
    double slip_state = 0.0;      // Gauss-Markov deviation from the mean slip
    double extra_slip = 0.0;      // injected fault
  };
  void AdvanceWheel(Wheel& wheel, double dt, double rotation, const garden::SlipModel* surface);

  int ticks_per_revolution_;
  Rng rng_;
  Wheel left_, right_;
};

}  // namespace trimbot::sim
