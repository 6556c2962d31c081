#include "trimbot/sim/faults.h"

#include <iomanip>
#include <sstream>

namespace trimbot::sim {

std::string Fault::Describe() const {
  std::ostringstream text;
  text << std::fixed << std::setprecision(3);
  switch (kind) {
    case Kind::kWheelSlip:
      text << "wheel slip left " << slip_left << " right " << slip_right;
      break;
    case Kind::kImuBiasJump:
      text << "IMU bias jump gyro [" << gyroscope_bias_jump.transpose() << "] rad/s accel ["
           << accelerometer_bias_jump.transpose() << "] m/s^2";
      break;
    case Kind::kCameraDropout:
      text << "camera dropout (all cameras)";
      break;
  }
  text << std::setprecision(1) << " at " << start << " s";
  if (kind != Kind::kImuBiasJump) text << " for " << duration << " s";
  return text.str();
}

}  // namespace trimbot::sim
