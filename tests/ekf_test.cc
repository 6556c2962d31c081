// The stack's pose EKF on its own (links only the stack: no simulator, no MuJoCo). The sensors are a
// simulated unicycle: exact wheel encoder counts and a biased, noisy gyro.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>

#include "trimbot/stack/ekf.h"

namespace trimbot::stack {
namespace {

const robot::DiffDriveGeometry kGeometry{0.115, 0.46};
constexpr int kTicksPerRevolution = 2048;
constexpr double kImuPeriod = 0.005;    // 200 Hz
constexpr int kImuSamplesPerTicks = 4;  // wheel ticks at 50 Hz
constexpr double kGyroBias = 0.01;      // rad/s
constexpr double kGyroNoise = 0.005;    // rad/s

double WrapAngle(double angle) { return std::remainder(angle, 2.0 * M_PI); }

// A unicycle driven by speed profiles, integrated in 1 ms steps along exact arcs. Its wheel
// distances come from the same speeds, so the encoder counts are exactly consistent with the pose.
class SimulatedBase {
 public:
  using Profile = std::function<double(double)>;
  SimulatedBase(Profile linear, Profile angular, std::uint32_t seed)
      : linear_(std::move(linear)), angular_(std::move(angular)), rng_(seed) {}

  void AdvanceTo(double t_end) {
    constexpr double kStep = 0.001;
    while (t_ < t_end - 1e-12) {
      const double h = std::min(kStep, t_end - t_);
      const double v = linear_(t_ + 0.5 * h), w = angular_(t_ + 0.5 * h);
      const double turn = w * h;
      const double chord = std::abs(turn) < 1e-9 ? v * h : 2.0 * v / w * std::sin(0.5 * turn);
      pose_.x += chord * std::cos(pose_.yaw + 0.5 * turn);
      pose_.y += chord * std::sin(pose_.yaw + 0.5 * turn);
      pose_.yaw = WrapAngle(pose_.yaw + turn);
      // The encoders read (1 + slip) times the ground's motion.
      left_distance_ += (1.0 + slip_) * (v - 0.5 * kGeometry.wheel_separation * w) * h;
      right_distance_ += (1.0 + slip_) * (v + 0.5 * kGeometry.wheel_separation * w) * h;
      t_ += h;
    }
  }

  messages::WheelTicks Ticks() const {
    const auto count = [](double distance) {
      return static_cast<std::int64_t>(
          std::floor(distance / kGeometry.wheel_radius * kTicksPerRevolution / (2.0 * M_PI)));
    };
    return {t_, count(left_distance_), count(right_distance_)};
  }

  messages::ImuSample Imu() {
    messages::ImuSample imu;
    imu.stamp = t_;
    imu.linear_acceleration = {0.0, 0.0, 9.81};
    imu.angular_velocity = {0.0, 0.0, angular_(t_) + kGyroBias + gyro_noise_(rng_)};
    return imu;
  }

  messages::PoseFix Fix(double position_sigma, double yaw_sigma) {
    std::normal_distribution<double> unit(0.0, 1.0);
    messages::PoseFix fix;
    fix.stamp = t_;
    fix.x = pose_.x + position_sigma * unit(rng_);
    fix.y = pose_.y + position_sigma * unit(rng_);
    fix.yaw = WrapAngle(pose_.yaw + yaw_sigma * unit(rng_));
    fix.covariance =
        Eigen::Vector3d(position_sigma * position_sigma, position_sigma * position_sigma, yaw_sigma * yaw_sigma)
            .asDiagonal();
    return fix;
  }

  double time() const { return t_; }
  const Pose2& pose() const { return pose_; }
  void set_slip(double slip) { slip_ = slip; }

 private:
  Profile linear_, angular_;
  std::mt19937 rng_;
  std::normal_distribution<double> gyro_noise_{0.0, kGyroNoise};
  double t_ = 0.0;
  Pose2 pose_;
  double left_distance_ = 0.0, right_distance_ = 0.0;
  double slip_ = 0.0;
};

// An arc of varying curvature at walking speed.
SimulatedBase ArcDrive(std::uint32_t seed) {
  return SimulatedBase([](double t) { return 0.3 + 0.1 * std::sin(0.2 * t); },
                       [](double t) { return 0.15 + 0.1 * std::sin(0.3 * t); }, seed);
}

// Calls `deliver` with the sensor messages of IMU step i (stamp i * 5 ms): the IMU sample, and wheel
// ticks on every 4th step (ticks first).
void StepSensors(SimulatedBase* base, int i, Ekf* ekf) {
  base->AdvanceTo(i * kImuPeriod);
  if (i % kImuSamplesPerTicks == 0) ekf->AddWheelTicks(base->Ticks());
  ekf->AddImu(base->Imu());
}

Ekf MakeEkf(const Pose2& start = {}, double start_sigma = 0.01, const EkfParameters& parameters = {}) {
  Ekf ekf(parameters, kGeometry, kTicksPerRevolution);
  ekf.Initialize(
      0.0, start,
      Eigen::Vector3d(start_sigma * start_sigma, start_sigma * start_sigma, start_sigma * start_sigma).asDiagonal());
  return ekf;
}

double PositionError(const Ekf& ekf, const SimulatedBase& base) {
  const PoseEstimate estimate = ekf.Estimate();
  return std::hypot(estimate.pose.x - base.pose().x, estimate.pose.y - base.pose().y);
}
double YawError(const Ekf& ekf, const SimulatedBase& base) {
  return std::abs(WrapAngle(ekf.Estimate().pose.yaw - base.pose().yaw));
}

bool StateIsFinite(const Ekf& ekf) { return ekf.state().allFinite() && ekf.covariance().allFinite(); }

// Drives 2 s on the arc so the filter has history, then returns.
void WarmUp(SimulatedBase* base, Ekf* ekf, int* step) {
  for (; *step <= 400; ++*step) StepSensors(base, *step, ekf);
}

TEST(Ekf, FollowsAnArcOnWheelsAndGyro) {
  SimulatedBase base = ArcDrive(1);
  Ekf ekf = MakeEkf();
  double worst_position = 0.0, worst_yaw = 0.0;
  // Speed errors over the last 10 s: the turn rate follows each gyro sample (5 mrad/s noise), so
  // look at their mean (bias) and RMS rather than at one instant.
  double linear_error_sum = 0.0, linear_error_squares = 0.0;
  double angular_error_sum = 0.0, angular_error_squares = 0.0;
  int speed_samples = 0;
  for (int i = 0; i <= 6000; ++i) {  // 30 s, about 9 m of arc
    StepSensors(&base, i, &ekf);
    worst_position = std::max(worst_position, PositionError(ekf, base));
    worst_yaw = std::max(worst_yaw, YawError(ekf, base));
    if (base.time() >= 20.0) {
      const PoseEstimate estimate = ekf.Estimate();
      const double linear_error = estimate.linear_velocity - (0.3 + 0.1 * std::sin(0.2 * base.time()));
      const double angular_error = estimate.angular_velocity - (0.15 + 0.1 * std::sin(0.3 * base.time()));
      linear_error_sum += linear_error;
      linear_error_squares += linear_error * linear_error;
      angular_error_sum += angular_error;
      angular_error_squares += angular_error * angular_error;
      ++speed_samples;
    }
  }
  const double linear_mean = linear_error_sum / speed_samples;
  const double linear_rms = std::sqrt(linear_error_squares / speed_samples);
  const double angular_mean = angular_error_sum / speed_samples;
  const double angular_rms = std::sqrt(angular_error_squares / speed_samples);
  std::printf(
      "dead reckoning over 30 s: worst position error %.4f m, worst yaw error %.3f deg, "
      "bias estimate %.5f rad/s; last 10 s: v error mean %.4f rms %.4f m/s, w error mean %.4f "
      "rms %.4f rad/s\n",
      worst_position, worst_yaw * 180.0 / M_PI, ekf.Estimate().gyro_bias, linear_mean, linear_rms, angular_mean,
      angular_rms);
  EXPECT_DOUBLE_EQ(ekf.Estimate().stamp, 30.0);
  EXPECT_LT(worst_position, 0.05);
  EXPECT_LT(worst_yaw, 2.0 * M_PI / 180.0);
  EXPECT_LT(std::abs(linear_mean), 0.005);
  EXPECT_LT(linear_rms, 0.02);
  EXPECT_LT(std::abs(angular_mean), 0.002);
  EXPECT_LT(angular_rms, 0.01);
  EXPECT_EQ(ekf.counters().inputs_dropped, 0);
}

// Normalized estimation error squared of (x, y, yaw) under the filter's own covariance.
double Nees(const Ekf& ekf, const SimulatedBase& base) {
  const PoseEstimate estimate = ekf.Estimate();
  const Eigen::Vector3d error(estimate.pose.x - base.pose().x, estimate.pose.y - base.pose().y,
                              WrapAngle(estimate.pose.yaw - base.pose().yaw));
  return error.dot(estimate.covariance.inverse() * error);
}

struct SlipRun {
  double wheel_scale = 0.0;        // mean estimate over the last 60 s
  double wheel_scale_sigma = 0.0;  // the filter's, at the end
  double mean_nees = 0.0;          // over the last 60 s, at 10 Hz
};

// The arc for 120 s with wheels that read 3 % more than the ground moved (grass), and fixes as the
// real visual localization gave them (5.5 cm per axis, 1.15 deg, every 0.25 s, 150 ms late).
SlipRun DriveOnSlippingWheels(const EkfParameters& parameters) {
  SimulatedBase base = ArcDrive(3);
  base.set_slip(0.03);
  Ekf ekf = MakeEkf({}, 0.01, parameters);
  std::deque<messages::PoseFix> in_flight;
  double nees_sum = 0.0, scale_sum = 0.0;
  int nees_count = 0;
  for (int i = 0; i <= 24000; ++i) {
    StepSensors(&base, i, &ekf);
    if (i % 50 == 0) in_flight.push_back(base.Fix(0.055, 1.15 * M_PI / 180.0));
    while (!in_flight.empty() && in_flight.front().stamp <= base.time() - 0.15 + 1e-9) {
      ekf.AddPoseFix(in_flight.front());
      in_flight.pop_front();
    }
    if (base.time() >= 60.0 && i % 20 == 0) {
      nees_sum += Nees(ekf, base);
      scale_sum += ekf.Estimate().wheel_scale;
      ++nees_count;
    }
  }
  return {scale_sum / nees_count, std::sqrt(ekf.covariance()(6, 6)), nees_sum / nees_count};
}

// Biased slip, estimated as a state, leaves the filter consistent (mean NEES near 3, the mean of
// chi-square with 3 dof); treated as white noise alone (the slip state pinned at 0), it does not.
TEST(Ekf, EstimatesWheelSlipAndStaysConsistent) {
  const SlipRun with_state = DriveOnSlippingWheels(EkfParameters{});
  EkfParameters pinned;
  pinned.wheel_scale_sigma = 1e-6;
  pinned.wheel_scale_random_walk = 0.0;
  const SlipRun without_state = DriveOnSlippingWheels(pinned);
  std::printf("slip 0.030: estimated %.4f (sigma %.4f), mean NEES %.2f; with the slip state pinned: mean NEES %.2f\n",
              with_state.wheel_scale, with_state.wheel_scale_sigma, with_state.mean_nees, without_state.mean_nees);
  EXPECT_NEAR(with_state.wheel_scale, 0.03, 0.01);
  // 600 samples, correlated over seconds: a wide band around 3.
  EXPECT_GT(with_state.mean_nees, 1.5);
  EXPECT_LT(with_state.mean_nees, 5.0);
  EXPECT_GT(without_state.mean_nees, with_state.mean_nees);
}

// Fixes from a map that is off by the same few centimetres wherever the robot is (a log-built map's
// scale and calibration biases): each fix states 2 cm shared plus 1 cm of its own per axis. Averaged
// as independent, 240 such fixes make the filter claim millimetres while it stays off by the shared
// error; with the shared error as a state, its covariance keeps it.
double MeanNeesWithASharedFixError(double shared_fix_error_sigma) {
  EkfParameters parameters;
  parameters.shared_fix_error_sigma = shared_fix_error_sigma;
  SimulatedBase base = ArcDrive(4);
  Ekf ekf = MakeEkf({}, 0.01, parameters);
  const Eigen::Vector2d shared_error(0.02, -0.015);  // about one sigma per axis
  constexpr double kOwnSigma = 0.01, kSharedSigma = 0.02;
  const double stated_sigma = std::hypot(kOwnSigma, kSharedSigma);
  double nees_sum = 0.0;
  int nees_count = 0;
  for (int i = 0; i <= 24000; ++i) {
    StepSensors(&base, i, &ekf);
    if (i % 100 == 0) {
      messages::PoseFix fix = base.Fix(kOwnSigma, 0.5 * M_PI / 180.0);
      fix.x += shared_error.x();
      fix.y += shared_error.y();
      fix.covariance(0, 0) = fix.covariance(1, 1) = stated_sigma * stated_sigma;
      ekf.AddPoseFix(fix);
    }
    if (base.time() >= 60.0 && i % 20 == 0) {
      nees_sum += Nees(ekf, base);
      ++nees_count;
    }
  }
  return nees_sum / nees_count;
}

TEST(Ekf, ASharedFixErrorAsAStateKeepsTheFilterConsistent) {
  const double with_state = MeanNeesWithASharedFixError(0.02);
  const double without_state = MeanNeesWithASharedFixError(0.0);
  std::printf("fixes off by a shared 2.5 cm: mean NEES %.2f with the shared error as a state, %.2f without\n",
              with_state, without_state);
  EXPECT_GT(with_state, 1.0);
  EXPECT_LT(with_state, 5.0);
  EXPECT_GT(without_state, 3.0 * with_state);
  // The source's shared error is set before the first input, never after (it would rewrite the past).
  Ekf ekf = MakeEkf();
  ekf.SetSharedFixError(0.02, 10.0);
  EXPECT_NEAR(std::sqrt(ekf.covariance()(7, 7)), 0.02, 1e-12);
  SimulatedBase base = ArcDrive(5);
  StepSensors(&base, 0, &ekf);
  EXPECT_THROW(ekf.SetSharedFixError(0.02, 10.0), std::logic_error);
}

TEST(Ekf, GyroBiasConvergesWithLateFixes) {
  SimulatedBase base = ArcDrive(2);
  Ekf ekf = MakeEkf();
  // Fixes every 0.5 s (2 cm, 0.5 deg), each delivered 150 ms after its capture time.
  std::deque<messages::PoseFix> in_flight;
  double worst_position = 0.0, worst_yaw = 0.0;
  for (int i = 0; i <= 24000; ++i) {  // 120 s
    StepSensors(&base, i, &ekf);
    if (i % 100 == 0) in_flight.push_back(base.Fix(0.02, 0.5 * M_PI / 180.0));
    while (!in_flight.empty() && in_flight.front().stamp <= base.time() - 0.15 + 1e-9) {
      const FixOutcome outcome = ekf.AddPoseFix(in_flight.front());
      EXPECT_TRUE(outcome == FixOutcome::kAccepted || outcome == FixOutcome::kRejectedOutlier);
      in_flight.pop_front();
    }
    if (base.time() >= 60.0) {
      worst_position = std::max(worst_position, PositionError(ekf, base));
      worst_yaw = std::max(worst_yaw, YawError(ekf, base));
    }
  }
  const PoseEstimate estimate = ekf.Estimate();
  std::printf(
      "with fixes, last 60 s: worst position error %.4f m, worst yaw error %.3f deg; "
      "bias %.5f rad/s (true %.3f), bias sigma %.5f; %d fixes rejected\n",
      worst_position, worst_yaw * 180.0 / M_PI, estimate.gyro_bias, kGyroBias, std::sqrt(ekf.covariance()(5, 5)),
      ekf.counters().fixes_rejected);
  EXPECT_NEAR(estimate.gyro_bias, kGyroBias, 0.002);
  // Twice the fixes' 2 cm: the filter does not know these wheels are exact (its slip state, a few
  // percent), so it follows the fixes more than wheels it could trust (3.2 cm worst, 2.2 cm before
  // the slip state).
  EXPECT_LT(worst_position, 0.04);
  EXPECT_LT(worst_yaw, 1.0 * M_PI / 180.0);
  // A consistent filter rejects about 1 % of good fixes at the 99 % gate.
  EXPECT_EQ(ekf.counters().fixes_accepted + ekf.counters().fixes_rejected, 240);
  EXPECT_LE(ekf.counters().fixes_rejected, 8);
  EXPECT_EQ(ekf.counters().relocalizations, 0);
}

TEST(Ekf, LateFixEqualsTheSameFixInTimeOrder) {
  SimulatedBase base_late = ArcDrive(3), base_in_order = ArcDrive(3), base_without = ArcDrive(3);
  Ekf late = MakeEkf(), in_order = MakeEkf(), without = MakeEkf();
  // Captured between sensor stamps (5.0125 s), offset 5 cm so that it visibly moves the estimate.
  constexpr int kFixAfterStep = 1002;  // 5.010 s
  constexpr int kLateBySteps = 60;     // delivered 0.3 s later
  messages::PoseFix fix;
  for (int i = 0; i <= 1400; ++i) {
    StepSensors(&base_late, i, &late);
    StepSensors(&base_in_order, i, &in_order);
    StepSensors(&base_without, i, &without);
    if (i == kFixAfterStep) {
      SimulatedBase truth = ArcDrive(3);  // its own, so that the sensors' noise stays in step
      truth.AdvanceTo(base_in_order.time() + 0.0025);
      fix.stamp = truth.time();
      fix.x = truth.pose().x + 0.05;
      fix.y = truth.pose().y;
      fix.yaw = truth.pose().yaw;
      fix.covariance = Eigen::Vector3d(0.03 * 0.03, 0.03 * 0.03, 0.02 * 0.02).asDiagonal();
      ASSERT_EQ(in_order.AddPoseFix(fix), FixOutcome::kAccepted);
      ASSERT_DOUBLE_EQ(in_order.Estimate().stamp, fix.stamp);  // the fix was the newest input
    }
    if (i == kFixAfterStep + kLateBySteps) {
      ASSERT_NEAR(late.Estimate().stamp - fix.stamp, 0.3 - 0.0025, 1e-9);
      ASSERT_EQ(late.AddPoseFix(fix), FixOutcome::kAccepted);
    }
  }
  const double state_difference = (late.state() - in_order.state()).cwiseAbs().maxCoeff();
  const double covariance_difference = (late.covariance() - in_order.covariance()).cwiseAbs().maxCoeff();
  const double fix_effect = (late.state() - without.state()).head<2>().norm();
  std::printf("late vs in order: state %.3g, covariance %.3g; effect of the fix %.4f m\n", state_difference,
              covariance_difference, fix_effect);
  EXPECT_LT(state_difference, 1e-9);
  EXPECT_LT(covariance_difference, 1e-9);
  EXPECT_GT(fix_effect, 0.01);  // the comparison is not vacuous
  EXPECT_DOUBLE_EQ(late.Estimate().stamp, in_order.Estimate().stamp);
}

TEST(Ekf, SensorsOutOfOrderAcrossSensorsEqualTimeOrder) {
  // The IMU driver may deliver a sample after newer wheel ticks; it is applied at its own stamp.
  SimulatedBase base_sorted = ArcDrive(4), base_shuffled = ArcDrive(4);
  Ekf sorted = MakeEkf(), shuffled = MakeEkf();
  std::deque<messages::ImuSample> imu_queue;
  for (int i = 0; i <= 800; ++i) {
    StepSensors(&base_sorted, i, &sorted);
    base_shuffled.AdvanceTo(i * kImuPeriod);
    if (i % kImuSamplesPerTicks == 0) shuffled.AddWheelTicks(base_shuffled.Ticks());
    imu_queue.push_back(base_shuffled.Imu());
    if (imu_queue.size() > 3) {  // IMU samples arrive 15 ms late
      shuffled.AddImu(imu_queue.front());
      imu_queue.pop_front();
    }
  }
  for (; !imu_queue.empty(); imu_queue.pop_front()) shuffled.AddImu(imu_queue.front());
  EXPECT_LT((sorted.state() - shuffled.state()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((sorted.covariance() - shuffled.covariance()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(shuffled.counters().inputs_dropped, 0);
}

TEST(Ekf, RejectsAnOutlierAndRelocalizesOnAConsistentRun) {
  SimulatedBase base = ArcDrive(5);
  Ekf ekf = MakeEkf();
  int step = 0;
  WarmUp(&base, &ekf, &step);
  const auto fix_at = [&](double dx, double dy) {
    messages::PoseFix fix = base.Fix(0.0, 0.0);
    fix.x += dx;
    fix.y += dy;
    fix.covariance = Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 0.03 * 0.03).asDiagonal();
    return fix;
  };
  const auto drive = [&](int steps) {
    for (const int end = step + steps; step <= end; ++step) StepSensors(&base, step, &ekf);
  };

  // A 2 m outlier is rejected and changes nothing.
  const Ekf::StateVector before = ekf.state();
  EXPECT_EQ(ekf.AddPoseFix(fix_at(2.0, 0.0)), FixOutcome::kRejectedOutlier);
  EXPECT_EQ(ekf.counters().fixes_rejected, 1);
  EXPECT_EQ((ekf.state() - before).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT(PositionError(ekf, base), 0.03);

  // A good fix is accepted and ends the rejected run.
  drive(20);
  EXPECT_EQ(ekf.AddPoseFix(fix_at(0.0, 0.0)), FixOutcome::kAccepted);

  // Rejected fixes that disagree with each other never add up to a re-localization.
  for (int k = 0; k < 6; ++k) {
    drive(20);
    EXPECT_EQ(ekf.AddPoseFix(fix_at(k % 2 == 0 ? 1.5 : -1.5, 0.0)), FixOutcome::kRejectedOutlier);
  }
  EXPECT_EQ(ekf.counters().relocalizations, 0);
  EXPECT_LT(PositionError(ekf, base), 0.03);

  // Five consistent fixes 1.5 m away (the filter is the one that is wrong): the first four are
  // rejected, the fifth re-localizes and the estimate jumps to them.
  const double jitter[5] = {0.0, 0.1, -0.1, 0.05, 0.02};
  for (int k = 0; k < 5; ++k) {
    drive(20);
    const FixOutcome outcome = ekf.AddPoseFix(fix_at(0.0, 1.5 + jitter[k]));
    EXPECT_EQ(outcome, k < 4 ? FixOutcome::kRejectedOutlier : FixOutcome::kRelocalized) << "fix " << k;
  }
  EXPECT_EQ(ekf.counters().relocalizations, 1);
  EXPECT_EQ(ekf.counters().fixes_rejected, 1 + 6 + 4);
  const PoseEstimate estimate = ekf.Estimate();
  EXPECT_NEAR(estimate.pose.x, base.pose().x, 0.01);
  EXPECT_NEAR(estimate.pose.y, base.pose().y + 1.52, 0.01);
  EXPECT_NEAR(estimate.covariance(0, 0), 0.05 * 0.05, 1e-4);  // the fix's own uncertainty

  // The filter now follows the new story: the next fix there is accepted.
  drive(20);
  EXPECT_EQ(ekf.AddPoseFix(fix_at(0.0, 1.52)), FixOutcome::kAccepted);
  EXPECT_TRUE(StateIsFinite(ekf));
}

TEST(Ekf, FixOlderThanTheHistoryIsTooOld) {
  SimulatedBase base = ArcDrive(6);
  Ekf ekf = MakeEkf();
  int step = 0;
  WarmUp(&base, &ekf, &step);                                   // 2 s
  for (; step <= 1000; ++step) StepSensors(&base, step, &ekf);  // 5 s
  messages::PoseFix fix = base.Fix(0.02, 0.01);
  fix.stamp = ekf.Estimate().stamp - EkfParameters{}.history_seconds - 0.01;
  const Ekf::StateVector before = ekf.state();
  EXPECT_EQ(ekf.AddPoseFix(fix), FixOutcome::kTooOld);
  EXPECT_EQ(ekf.counters().fixes_too_old, 1);
  EXPECT_EQ((ekf.state() - before).cwiseAbs().maxCoeff(), 0.0);
  // Just inside the history it can still be applied.
  fix.stamp += 0.02;
  EXPECT_NE(ekf.AddPoseFix(fix), FixOutcome::kTooOld);
}

TEST(Ekf, FixFromTheFutureIsInvalidAndSensorsGoOn) {
  SimulatedBase base = ArcDrive(8);
  Ekf ekf = MakeEkf();
  int step = 0;
  WarmUp(&base, &ekf, &step);
  messages::PoseFix fix = base.Fix(0.02, 0.01);
  fix.stamp = ekf.Estimate().stamp + 10.0;  // a clock glitch
  EXPECT_EQ(ekf.AddPoseFix(fix), FixOutcome::kInvalid);
  const int dropped = ekf.counters().inputs_dropped;
  for (int end = step + 200; step < end; ++step) StepSensors(&base, step, &ekf);
  EXPECT_EQ(ekf.counters().inputs_dropped, dropped) << "sensor inputs after the bad fix were dropped";
  EXPECT_LT(PositionError(ekf, base), 0.05);
}

TEST(Ekf, InvalidInputsAreDroppedAndCounted) {
  SimulatedBase base = ArcDrive(7);
  Ekf uninitialized(EkfParameters{}, kGeometry, kTicksPerRevolution);
  EXPECT_EQ(uninitialized.AddPoseFix(base.Fix(0.02, 0.01)), FixOutcome::kInvalid);
  uninitialized.AddImu(base.Imu());
  uninitialized.AddWheelTicks(base.Ticks());
  EXPECT_EQ(uninitialized.counters().inputs_dropped, 3);
  EXPECT_FALSE(uninitialized.initialized());

  Ekf ekf = MakeEkf();
  int step = 0;
  WarmUp(&base, &ekf, &step);
  const Ekf::StateVector state = ekf.state();
  const Ekf::StateMatrix covariance = ekf.covariance();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  int dropped = 0;

  messages::PoseFix nan_fix = base.Fix(0.02, 0.01);
  nan_fix.x = nan;
  EXPECT_EQ(ekf.AddPoseFix(nan_fix), FixOutcome::kInvalid);
  ++dropped;

  messages::PoseFix nan_covariance = base.Fix(0.02, 0.01);
  nan_covariance.covariance(2, 2) = nan;
  EXPECT_EQ(ekf.AddPoseFix(nan_covariance), FixOutcome::kInvalid);
  ++dropped;

  messages::PoseFix indefinite = base.Fix(0.02, 0.01);
  indefinite.covariance(0, 1) = indefinite.covariance(1, 0) = 1.0;  // |correlation| > 1
  EXPECT_EQ(ekf.AddPoseFix(indefinite), FixOutcome::kInvalid);
  ++dropped;

  messages::PoseFix negative = base.Fix(0.02, 0.01);
  negative.covariance(2, 2) = -1e-4;
  EXPECT_EQ(ekf.AddPoseFix(negative), FixOutcome::kInvalid);
  ++dropped;

  messages::PoseFix asymmetric = base.Fix(0.02, 0.01);
  asymmetric.covariance(0, 1) = 1e-5;  // (1, 0) stays 0
  EXPECT_EQ(ekf.AddPoseFix(asymmetric), FixOutcome::kInvalid);
  ++dropped;

  messages::WheelTicks backwards = base.Ticks();  // same stamp as the last ticks: not after them
  backwards.left += 100;
  ekf.AddWheelTicks(backwards);
  ++dropped;
  backwards.stamp -= 0.1;
  ekf.AddWheelTicks(backwards);
  ++dropped;

  messages::ImuSample imu = base.Imu();  // the last sample again
  ekf.AddImu(imu);
  ++dropped;
  imu.stamp += 0.001;
  imu.angular_velocity.z() = nan;
  ekf.AddImu(imu);
  ++dropped;
  imu.angular_velocity.z() = std::numeric_limits<double>::infinity();
  ekf.AddImu(imu);
  ++dropped;

  EXPECT_EQ(ekf.counters().inputs_dropped, dropped);
  EXPECT_EQ(ekf.counters().fixes_accepted + ekf.counters().fixes_rejected, 0);
  EXPECT_TRUE(StateIsFinite(ekf));
  EXPECT_EQ((ekf.state() - state).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((ekf.covariance() - covariance).cwiseAbs().maxCoeff(), 0.0);

  // The filter carries on normally afterwards (the dropped ticks did not become the reference).
  for (const int end = step + 200; step <= end; ++step) StepSensors(&base, step, &ekf);
  EXPECT_EQ(ekf.counters().inputs_dropped, dropped);
  EXPECT_LT(PositionError(ekf, base), 0.03);
  EXPECT_TRUE(StateIsFinite(ekf));
}

TEST(Ekf, YawStaysWrapped) {
  // Turning on the spot for several turns.
  SimulatedBase base([](double) { return 0.0; }, [](double) { return 1.0; }, 8);
  Ekf ekf = MakeEkf();
  for (int i = 0; i <= 4000; ++i) {  // 20 s, about 3 turns
    StepSensors(&base, i, &ekf);
    const double yaw = ekf.Estimate().pose.yaw;
    ASSERT_GT(yaw, -M_PI);
    ASSERT_LE(yaw, M_PI);
  }
  EXPECT_LT(YawError(ekf, base), 2.0 * M_PI / 180.0);
  EXPECT_LT(PositionError(ekf, base), 0.01);
}

}  // namespace
}  // namespace trimbot::stack
