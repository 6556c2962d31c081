#pragma once
// Faults injected into the simulated robot at scripted times (from the scenario file), applied by
// the simulator inside its fixed steps so a faulty run is as reproducible as a clean one.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace trimbot::sim {

struct Fault {
  enum class Kind {
    kWheelSlip,      // extra encoder slip on one or both wheels for `duration` (a muddy patch)
    kImuBiasJump,    // step change of the gyroscope / accelerometer bias at `start`
    kCameraDropout,  // no ring images (and so no visual pose fixes) for `duration`
  };
  Kind kind = Kind::kWheelSlip;
  double start = 0.0;     // s of simulated time
  double duration = 0.0;  // s (bias jumps are instantaneous and permanent)
  // kWheelSlip: extra slip fraction per wheel.
  double slip_left = 0.0, slip_right = 0.0;
  // kImuBiasJump.
  Eigen::Vector3d gyroscope_bias_jump = Eigen::Vector3d::Zero();      // rad/s
  Eigen::Vector3d accelerometer_bias_jump = Eigen::Vector3d::Zero();  // m/s^2

  bool ActiveAt(double t) const { return t >= start && t < start + duration; }
  // "wheel slip left 0.30 right 0.00 from 20.0 s for 5.0 s" - for summaries.
  std::string Describe() const;
};

}  // namespace trimbot::sim
