#pragma once
// Parameters of the robot that the URDF does not carry (robot/config/robot_parameters.yaml).
#include <array>
#include <string>

namespace trimbot::robot {

struct ImuNoise {
  std::string frame = "imu_link";
  double rate_hz = 200.0;
  double accelerometer_noise_density = 0.0;
  double accelerometer_random_walk = 0.0;
  double accelerometer_initial_bias_sigma = 0.0;
  double gyroscope_noise_density = 0.0;
  double gyroscope_random_walk = 0.0;
  double gyroscope_initial_bias_sigma = 0.0;
};

struct WheelEncoderConfig {
  double rate_hz = 50.0;
  int ticks_per_revolution = 2048;
};

// The sensors' automatic exposure (AEC/AGC): per image, the exposure brings the mean grey level
// of the metering window (the rows below `metering_top`, a fraction of the height: the ground, not
// the sky) to `target_mean`; by exposure time first (between `min_exposure_time` and
// `max_exposure_time`; the rendered daylight scene is exposed for `daylight_exposure_time`), then
// by analogue gain (up to `max_gain`, which amplifies the read noise too). The exposure time also
// sets the motion blur.
struct AutoExposure {
  bool enabled = true;
  double target_mean = 100.0;              // grey levels
  double metering_top = 0.4;               // 0..1
  double daylight_exposure_time = 1.5e-4;  // s
  double min_exposure_time = 3.2e-5;       // s
  double max_exposure_time = 0.0153;       // s
  double max_gain = 4.0;
  double max_exposure_factor() const { return max_exposure_time / daylight_exposure_time; }
  double min_exposure_factor() const { return min_exposure_time / daylight_exposure_time; }
};

struct CameraTiming {
  double rate_hz = 5.0;
  double noise_sigma = 2.0;
  AutoExposure auto_exposure;
};

struct DriveLimits {
  double max_linear_acceleration = 0.5;
  double max_angular_acceleration = 2.0;
  double max_linear_speed = 0.6;
  double max_angular_speed = 1.5;
};

struct RobotParameters {
  ImuNoise imu;
  WheelEncoderConfig wheel_encoders;
  CameraTiming cameras;
  DriveLimits drive;
  std::array<double, 6> arm_home_position{};  // rad

  // Throws InputError naming the file, line and key.
  static RobotParameters Load(const std::string& path);
};

}  // namespace trimbot::robot
