#include "trimbot/sim/imu_model.h"

#include <cmath>

namespace trimbot::sim {

ImuModel::ImuModel(const robot::ImuNoise& noise, std::uint64_t seed) : noise_(noise), rng_(MakeRng(seed, "imu")) {
  accelerometer_bias_ = Gaussian3() * noise_.accelerometer_initial_bias_sigma;
  gyroscope_bias_ = Gaussian3() * noise_.gyroscope_initial_bias_sigma;
}

Eigen::Vector3d ImuModel::Gaussian3() {
  const double x = StandardNormal(rng_);
  const double y = StandardNormal(rng_);
  const double z = StandardNormal(rng_);
  return {x, y, z};
}

messages::ImuSample ImuModel::Measure(double stamp, const Eigen::Vector3d& true_specific_force,
                                      const Eigen::Vector3d& true_angular_velocity, double period) {
  // Discrete-time equivalents of the continuous densities: white noise sigma / sqrt(dt), bias
  // random walk sigma * sqrt(dt) per step.
  const double sqrt_dt = std::sqrt(period);
  accelerometer_bias_ += Gaussian3() * (noise_.accelerometer_random_walk * sqrt_dt);
  gyroscope_bias_ += Gaussian3() * (noise_.gyroscope_random_walk * sqrt_dt);
  messages::ImuSample sample;
  sample.stamp = stamp;
  sample.linear_acceleration =
      true_specific_force + accelerometer_bias_ + Gaussian3() * (noise_.accelerometer_noise_density / sqrt_dt);
  sample.angular_velocity =
      true_angular_velocity + gyroscope_bias_ + Gaussian3() * (noise_.gyroscope_noise_density / sqrt_dt);
  return sample;
}

}  // namespace trimbot::sim
