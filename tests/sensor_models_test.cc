// Sensor and actuator models on their own: IMU noise statistics, encoder quantization and slip,
// the base controller's limits.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "trimbot/sim/arm_controller.h"
#include "trimbot/sim/base_controller.h"
#include "trimbot/sim/camera_exposure.h"
#include "trimbot/sim/camera_noise.h"
#include "trimbot/sim/imu_model.h"
#include "trimbot/sim/wheel_encoder_model.h"

namespace trimbot::sim {
namespace {

robot::ImuNoise Noise() {
  robot::ImuNoise noise;
  noise.rate_hz = 200.0;
  noise.accelerometer_noise_density = 2.0e-3;
  noise.accelerometer_random_walk = 3.0e-3;
  noise.accelerometer_initial_bias_sigma = 0.05;
  noise.gyroscope_noise_density = 1.7e-4;
  noise.gyroscope_random_walk = 2.0e-5;
  noise.gyroscope_initial_bias_sigma = 5.0e-3;
  return noise;
}

TEST(ImuModel, WhiteNoiseMatchesTheDensity) {
  robot::ImuNoise noise = Noise();
  noise.accelerometer_random_walk = noise.gyroscope_random_walk = 0.0;
  ImuModel imu(noise, 11);
  const double dt = 1.0 / noise.rate_hz;
  const Eigen::Vector3d gravity(0, 0, 9.81);
  const int n = 100000;
  Eigen::Vector3d sum_a = Eigen::Vector3d::Zero(), sum2_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_g = Eigen::Vector3d::Zero(), sum2_g = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const auto s = imu.Measure(i * dt, gravity, Eigen::Vector3d::Zero(), dt);
    const Eigen::Vector3d a = s.linear_acceleration - gravity - imu.accelerometer_bias();
    const Eigen::Vector3d g = s.angular_velocity - imu.gyroscope_bias();
    sum_a += a;
    sum2_a += a.cwiseProduct(a);
    sum_g += g;
    sum2_g += g.cwiseProduct(g);
  }
  const double expected_a = noise.accelerometer_noise_density / std::sqrt(dt);
  const double expected_g = noise.gyroscope_noise_density / std::sqrt(dt);
  for (int k = 0; k < 3; ++k) {
    // 100k samples: the standard deviation is known to ~0.3%; allow 2%.
    EXPECT_NEAR(std::sqrt(sum2_a[k] / n - std::pow(sum_a[k] / n, 2)), expected_a, 0.02 * expected_a);
    EXPECT_NEAR(std::sqrt(sum2_g[k] / n - std::pow(sum_g[k] / n, 2)), expected_g, 0.02 * expected_g);
    EXPECT_NEAR(sum_a[k] / n, 0.0, 5 * expected_a / std::sqrt(n));
  }
}

TEST(ImuModel, BiasRandomWalkGrowsWithTheSquareRootOfTime) {
  robot::ImuNoise noise = Noise();
  noise.accelerometer_initial_bias_sigma = noise.gyroscope_initial_bias_sigma = 0.0;
  const double dt = 1.0 / noise.rate_hz;
  const double duration = 50.0;
  const int runs = 300;
  double variance_a = 0.0, variance_g = 0.0;
  for (int run = 0; run < runs; ++run) {
    ImuModel imu(noise, 1000 + run);
    for (int i = 0; i < static_cast<int>(duration / dt); ++i) {
      imu.Measure(i * dt, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), dt);
    }
    variance_a += imu.accelerometer_bias().squaredNorm() / 3.0;
    variance_g += imu.gyroscope_bias().squaredNorm() / 3.0;
  }
  variance_a /= runs;
  variance_g /= runs;
  // 900 independent bias values: the variance is known to ~5%; allow 15%.
  const double expected_a = std::pow(noise.accelerometer_random_walk, 2) * duration;
  const double expected_g = std::pow(noise.gyroscope_random_walk, 2) * duration;
  EXPECT_NEAR(variance_a, expected_a, 0.15 * expected_a);
  EXPECT_NEAR(variance_g, expected_g, 0.15 * expected_g);
}

TEST(ImuModel, TurnOnBiasFollowsItsSigmaAndTheSeed) {
  const robot::ImuNoise noise = Noise();
  double sum2 = 0.0;
  const int runs = 2000;
  for (int run = 0; run < runs; ++run) sum2 += ImuModel(noise, run).gyroscope_bias().squaredNorm() / 3.0;
  EXPECT_NEAR(std::sqrt(sum2 / runs), noise.gyroscope_initial_bias_sigma, 0.05 * noise.gyroscope_initial_bias_sigma);
  EXPECT_EQ(ImuModel(noise, 5).gyroscope_bias(), ImuModel(noise, 5).gyroscope_bias());
  EXPECT_NE(ImuModel(noise, 5).gyroscope_bias(), ImuModel(noise, 6).gyroscope_bias());
}

TEST(WheelEncoderModel, CountsWholeTurnsWithoutSlipInTheAir) {
  WheelEncoderModel encoders(2048, 1);
  for (int i = 0; i < 1000; ++i) encoders.Advance(0.001, 2.0 * M_PI / 1000.0, -2.0 * M_PI / 1000.0, nullptr, nullptr);
  const auto ticks = encoders.Read(1.0);
  EXPECT_NEAR(ticks.left, 2048, 1);
  EXPECT_NEAR(ticks.right, -2048, 1);
  // Quantization: a rotation below one tick does not count.
  WheelEncoderModel fine(2048, 1);
  fine.Advance(0.001, 0.5 * 2.0 * M_PI / 2048, 0.0, nullptr, nullptr);
  EXPECT_EQ(fine.Read(0.0).left, 0);
}

TEST(WheelEncoderModel, SlipOnGrassMakesTheWheelsCountTooFar) {
  const garden::SlipModel grass = garden::PropertiesOf(garden::Surface::kGrass).slip;
  WheelEncoderModel encoders(2048, 3);
  const double dt = 0.0025, speed = 2.0;  // rad/s
  const int steps = static_cast<int>(600.0 / dt);
  for (int i = 0; i < steps; ++i) encoders.Advance(dt, speed * dt, speed * dt, &grass, &grass);
  const double true_ticks = speed * steps * dt * 2048 / (2.0 * M_PI);
  const auto ticks = encoders.Read(0.0);
  // Over 10 minutes the Gauss-Markov slip averages out to its mean (3% on grass).
  EXPECT_NEAR(ticks.left / true_ticks - 1.0, grass.mean, 0.005);
  EXPECT_NEAR(ticks.right / true_ticks - 1.0, grass.mean, 0.005);
  EXPECT_NE(ticks.left, ticks.right);  // the two wheels slip independently
}

TEST(BaseController, LimitsAccelerationAndSpeed) {
  const robot::DiffDriveGeometry geometry{0.115, 0.46};
  robot::DriveLimits limits;
  BaseController controller(geometry, limits);
  controller.SetCommand({2.0, 0.0});
  const double dt = 0.0025;
  for (int i = 0; i < 40; ++i) controller.Update(dt);  // 0.1 s
  EXPECT_NEAR(controller.linear(), limits.max_linear_acceleration * 0.1, 1e-9);
  for (int i = 0; i < 2000; ++i) controller.Update(dt);
  EXPECT_NEAR(controller.linear(), limits.max_linear_speed, 1e-9);
  controller.SetCommand({0.25, 0.5});
  for (int i = 0; i < 2000; ++i) controller.Update(dt);
  const robot::WheelSpeeds wheels = controller.Update(dt);
  EXPECT_NEAR(geometry.LinearFromWheels(wheels), 0.25, 1e-9);
  EXPECT_NEAR(geometry.AngularFromWheels(wheels), 0.5, 1e-9);
}

TEST(ArmController, VelocityModeIntegratesAndClampsToLimits) {
  std::array<JointRange, 6> ranges{};
  ranges[1] = {true, 0.82, 5.46};
  ArmController arm({0, 1.0, 0, 0, 0, 0}, ranges);
  messages::ArmCommand command;
  command.mode = messages::ArmCommand::Mode::kVelocity;
  command.velocity = {0.5, -0.5, 0, 0, 0, 0};
  arm.SetCommand(command);
  for (int i = 0; i < 400; ++i) arm.Update(0.0025);  // 1 s
  EXPECT_NEAR(arm.target()[0], 0.5, 1e-9);
  EXPECT_NEAR(arm.target()[1], 0.82, 1e-9);  // 1.0 - 0.5 clamped at the lower limit
}

// Evening: a dark ground under a bright sky. The metering window (the ground) is brought to the
// target by a longer exposure first, then by gain; a bright scene is darkened; off leaves it alone.
// The read-out scales the image by what was chosen and clips at 255.
TEST(AutoExposure, BringsTheGroundToTheTargetByExposureThenGain) {
  robot::AutoExposure ae;
  ae.target_mean = 100.0;
  ae.metering_top = 0.5;
  ae.daylight_exposure_time = 1e-3;
  ae.min_exposure_time = 0.5e-3;
  ae.max_exposure_time = 2e-3;
  ae.max_gain = 4.0;
  const ReadNoise noiseless(1, 16);
  cv::Mat image(100, 50, CV_8UC3, cv::Scalar(200, 200, 200));  // sky
  image.rowRange(50, 100).setTo(cv::Scalar(20, 30, 40));       // ground, mean 30
  const ExposureResult dark = MeterExposure(image, ae);
  EXPECT_NEAR(dark.exposure_factor, 2.0, 1e-9);
  EXPECT_NEAR(dark.gain, 100.0 / 30.0 / 2.0, 1e-9);
  noiseless.ReadOut(image, dark.exposure_factor * dark.gain, 0.0, 0);
  const cv::Scalar ground = cv::mean(image.rowRange(50, 100));
  EXPECT_NEAR((ground[0] + ground[1] + ground[2]) / 3.0, 100.0, 1.0);
  EXPECT_EQ(image.at<cv::Vec3b>(0, 0)[0], 255);  // the sky saturates

  cv::Mat bright(100, 50, CV_8UC3, cv::Scalar(220, 220, 220));
  const ExposureResult shorter = MeterExposure(bright, ae);
  EXPECT_NEAR(shorter.exposure_factor, 0.5, 1e-9);  // limited at 1/2
  EXPECT_EQ(shorter.gain, 1.0);
  noiseless.ReadOut(bright, shorter.exposure_factor * shorter.gain, 0.0, 0);
  EXPECT_EQ(bright.at<cv::Vec3b>(99, 0)[0], 110);

  ae.enabled = false;
  const cv::Mat untouched(10, 10, CV_8UC3, cv::Scalar(20, 20, 20));
  const ExposureResult off = MeterExposure(untouched, ae);
  EXPECT_EQ(off.gain, 1.0);
  EXPECT_EQ(off.exposure_factor, 1.0);
}

}  // namespace
}  // namespace trimbot::sim
