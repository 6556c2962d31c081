#include "trimbot/robot/robot_parameters.h"

#include <algorithm>
#include <cmath>

#include "trimbot/common/yaml_reader.h"

namespace trimbot::robot {
namespace {

// Rates, noise densities, accelerations and speeds: positive (or non-negative) and below `hi`, a
// bound far above any robot's but one that keeps 1e308 out.
double Positive(const YamlMap& map, const std::string& key, double hi = 1e4) { return map.Number(key, 1e-12, hi); }
double NonNegative(const YamlMap& map, const std::string& key, double hi = 1e3) { return map.Number(key, 0.0, hi); }

}  // namespace

RobotParameters RobotParameters::Load(const std::string& path) {
  const YamlMap root = YamlMap::LoadFile(path);
  RobotParameters config;

  const YamlMap imu = root.Map("imu");
  config.imu.frame = imu.String("frame");
  config.imu.rate_hz = Positive(imu, "rate_hz");
  config.imu.accelerometer_noise_density = NonNegative(imu, "accelerometer_noise_density");
  config.imu.accelerometer_random_walk = NonNegative(imu, "accelerometer_random_walk");
  config.imu.accelerometer_initial_bias_sigma = NonNegative(imu, "accelerometer_initial_bias_sigma");
  config.imu.gyroscope_noise_density = NonNegative(imu, "gyroscope_noise_density");
  config.imu.gyroscope_random_walk = NonNegative(imu, "gyroscope_random_walk");
  config.imu.gyroscope_initial_bias_sigma = NonNegative(imu, "gyroscope_initial_bias_sigma");
  imu.RejectUnknownKeys();

  const YamlMap encoders = root.Map("wheel_encoders");
  config.wheel_encoders.rate_hz = Positive(encoders, "rate_hz");
  config.wheel_encoders.ticks_per_revolution = encoders.Int("ticks_per_revolution");
  if (config.wheel_encoders.ticks_per_revolution <= 0) encoders.Fail("ticks_per_revolution", "must be positive");
  encoders.RejectUnknownKeys();

  const YamlMap cameras = root.Map("cameras");
  config.cameras.rate_hz = Positive(cameras, "rate_hz");
  config.cameras.noise_sigma = NonNegative(cameras, "noise_sigma");
  const YamlMap exposure = cameras.Map("auto_exposure");
  AutoExposure& ae = config.cameras.auto_exposure;
  ae.enabled = exposure.Bool("enabled");
  ae.target_mean = exposure.Number("target_mean", 1.0, 254.0, "grey levels");
  ae.metering_top = exposure.Number("metering_top", 0.0, 0.95);
  ae.daylight_exposure_time = exposure.Number("daylight_exposure_time", 1e-6, 1.0, "s");
  ae.min_exposure_time = exposure.Number("min_exposure_time", 1e-7, ae.daylight_exposure_time, "s");
  ae.max_exposure_time = exposure.Number("max_exposure_time", ae.daylight_exposure_time, 10.0, "s");
  ae.max_gain = exposure.Number("max_gain", 1.0, 1000.0);
  exposure.RejectUnknownKeys();
  cameras.RejectUnknownKeys();

  const YamlMap drive = root.Map("drive");
  config.drive.max_linear_acceleration = Positive(drive, "max_linear_acceleration");
  config.drive.max_angular_acceleration = Positive(drive, "max_angular_acceleration");
  config.drive.max_linear_speed = Positive(drive, "max_linear_speed");
  config.drive.max_angular_speed = Positive(drive, "max_angular_speed");
  drive.RejectUnknownKeys();

  const YamlMap arm = root.Map("arm");
  const auto home = arm.Numbers("home_position", 6, -2.0 * M_PI, 2.0 * M_PI, "rad");
  std::copy(home.begin(), home.end(), config.arm_home_position.begin());
  arm.RejectUnknownKeys();

  root.RejectUnknownKeys();
  return config;
}

}  // namespace trimbot::robot
