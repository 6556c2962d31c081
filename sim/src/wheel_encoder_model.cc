#include "trimbot/sim/wheel_encoder_model.h"

#include <cmath>

namespace trimbot::sim {

WheelEncoderModel::WheelEncoderModel(int ticks_per_revolution, std::uint64_t seed)
    : ticks_per_revolution_(ticks_per_revolution), rng_(MakeRng(seed, "wheel_encoders")) {}

void WheelEncoderModel::AdvanceWheel(Wheel& wheel, double dt, double rotation, const garden::SlipModel* surface) {
  double slip = 0.0;
  if (surface != nullptr) {
    const double decay = std::exp(-dt / surface->correlation_time);
    wheel.slip_state =
        decay * wheel.slip_state + surface->sigma * std::sqrt(1.0 - decay * decay) * StandardNormal(rng_);
    slip = surface->mean + wheel.slip_state + wheel.extra_slip;
  }
  wheel.measured_angle += rotation * (1.0 + slip);
}

void WheelEncoderModel::Advance(double dt, double rotation_left, double rotation_right,
                                const garden::SlipModel* surface_left, const garden::SlipModel* surface_right) {
  AdvanceWheel(left_, dt, rotation_left, surface_left);
  AdvanceWheel(right_, dt, rotation_right, surface_right);
}

messages::WheelTicks WheelEncoderModel::Read(double stamp) const {
  const double ticks_per_radian = ticks_per_revolution_ / (2.0 * M_PI);
  messages::WheelTicks ticks;
  ticks.stamp = stamp;
  ticks.left = static_cast<std::int64_t>(std::floor(left_.measured_angle * ticks_per_radian));
  ticks.right = static_cast<std::int64_t>(std::floor(right_.measured_angle * ticks_per_radian));
  return ticks;
}

}  // namespace trimbot::sim
