#pragma once
// IMU error model: white noise plus a bias that random-walks, per axis, for the accelerometer and
// the gyroscope (Kalibr's model). Takes the true specific force and angular rate, returns the
// measurement; the current biases are kept for the evaluation.
#include <Eigen/Core>
#include <cstdint>
#include <random>

#include "trimbot/common/random.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/robot_parameters.h"

namespace trimbot::sim {

class ImuModel {
 public:
  ImuModel(const robot::ImuNoise& noise, std::uint64_t seed);

  // One sample; `period` is the time since the previous sample (it scales noise and bias walk).
  messages::ImuSample Measure(double stamp, const Eigen::Vector3d& true_specific_force,
                              const Eigen::Vector3d& true_angular_velocity, double period);

  const Eigen::Vector3d& accelerometer_bias() const { return accelerometer_bias_; }
  const Eigen::Vector3d& gyroscope_bias() const { return gyroscope_bias_; }
  // Faults: a sudden bias change (e.g. a temperature jump).
  void AddGyroscopeBias(const Eigen::Vector3d& delta) { gyroscope_bias_ += delta; }
  void AddAccelerometerBias(const Eigen::Vector3d& delta) { accelerometer_bias_ += delta; }

 private:
  Eigen::Vector3d Gaussian3();

  robot::ImuNoise noise_;
  Rng rng_;
  Eigen::Vector3d accelerometer_bias_;
  Eigen::Vector3d gyroscope_bias_;
};

}  // namespace trimbot::sim
