#include "trimbot/stack/ekf.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <stdexcept>
#include <vector>

namespace trimbot::stack {
namespace {

using StateVector = Ekf::StateVector;
using StateMatrix = Ekf::StateMatrix;
constexpr int kN = Ekf::kStateSize;

// State layout.
constexpr int kX = 0, kY = 1, kYaw = 2, kV = 3, kW = 4, kBias = 5, kScale = 6, kSharedX = 7, kSharedY = 8;

// Prior on the states Initialize() is not told about. The first wheel speeds settle v and w at
// once; the bias prior is a MEMS gyro's turn-on bias (about 1 deg/s).
constexpr double kInitialSpeedSigma = 1.0;      // m/s
constexpr double kInitialTurnRateSigma = 1.0;   // rad/s
constexpr double kInitialGyroBiasSigma = 0.02;  // rad/s

// To (-pi, pi].
double WrapHeading(double angle) {
  double wrapped = WrapAngle(angle);
  if (wrapped <= -M_PI) wrapped += 2.0 * M_PI;
  return wrapped;
}

bool IsSymmetricPositiveDefinite(const Eigen::Matrix3d& m) {
  if (!m.allFinite()) return false;
  const double scale = std::max(1.0, m.cwiseAbs().maxCoeff());
  if ((m - m.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) return false;
  return Eigen::LLT<Eigen::Matrix3d>(m).info() == Eigen::Success;
}

// sin(a)/a and its derivative; Taylor series near 0, where the quotients cancel (their error there
// is below 1e-20, the closed forms' below 1e-11).
double Sinc(double a) {
  const double a2 = a * a;
  if (std::abs(a) < 1e-2) return 1.0 - a2 / 6.0 * (1.0 - a2 / 20.0 * (1.0 - a2 / 42.0));
  return std::sin(a) / a;
}
double SincDerivative(double a) {
  const double a2 = a * a;
  if (std::abs(a) < 1e-2) return -a / 3.0 * (1.0 - a2 / 10.0 * (1.0 - a2 / 28.0 * (1.0 - a2 / 54.0)));
  return (a * std::cos(a) - std::sin(a)) / a2;
}

// Constant-velocity unicycle over dt: the pose moves along the arc of constant (v, w); v, w and the
// bias stay. The arc's chord has length v dt sinc(w dt / 2) along the mid-step heading, which is
// exact and, unlike (v / w)(sin(yaw + w dt) - sin(yaw)), stays accurate as w -> 0. Returns the
// moved state and the exact Jacobian of that motion.
void PropagateMotion(const StateVector& x, double dt, StateVector* moved, StateMatrix* F) {
  // v is the speed the wheels turn at; the base moves over the ground at v / (1 + wheel_scale).
  const double v = x(kV), w = x(kW);
  const double per_ground = 1.0 / (1.0 + x(kScale));
  const double ground = v * per_ground;
  const double half_turn = 0.5 * w * dt;
  const double heading = x(kYaw) + half_turn;  // of the chord
  const double c = std::cos(heading), s = std::sin(heading);
  const double chord = ground * dt * Sinc(half_turn);
  const double chord_per_w = ground * dt * SincDerivative(half_turn) * 0.5 * dt;  // d chord / d w
  const double chord_per_scale = -chord * per_ground;                             // d chord / d wheel_scale
  *moved = x;
  (*moved)(kX) += chord * c;
  (*moved)(kY) += chord * s;
  (*moved)(kYaw) = WrapHeading(x(kYaw) + w * dt);
  F->setIdentity();
  (*F)(kX, kYaw) = -chord * s;
  (*F)(kY, kYaw) = chord * c;
  (*F)(kX, kV) = per_ground * dt * Sinc(half_turn) * c;
  (*F)(kY, kV) = per_ground * dt * Sinc(half_turn) * s;
  (*F)(kX, kScale) = chord_per_scale * c;
  (*F)(kY, kScale) = chord_per_scale * s;
  (*F)(kX, kW) = chord_per_w * c - chord * s * 0.5 * dt;
  (*F)(kY, kW) = chord_per_w * s + chord * c * 0.5 * dt;
  (*F)(kYaw, kW) = dt;
}

// Discrete process noise of white accelerations over dt: per channel the constant-velocity model's
// [dt^3/3, dt^2/2; dt^2/2, dt] * density^2. Linear acceleration moves the position along the
// (mid-step) heading; angular acceleration moves yaw. The cross-track position noise that a yaw
// error causes is O(dt^4) and left to the Jacobian of the next steps.
StateMatrix ProcessNoise(const StateVector& x, double dt, const EkfParameters& p) {
  const double q_linear = p.linear_acceleration_density * p.linear_acceleration_density;
  const double q_angular = p.angular_acceleration_density * p.angular_acceleration_density;
  const double q_bias = p.gyro_bias_random_walk * p.gyro_bias_random_walk;
  const double heading = x(kYaw) + 0.5 * x(kW) * dt;
  const Eigen::Vector2d along(std::cos(heading), std::sin(heading));
  const double dt2 = dt * dt, dt3 = dt2 * dt;
  StateMatrix Q = StateMatrix::Zero();
  Q.block<2, 2>(kX, kX) = q_linear * dt3 / 3.0 * along * along.transpose();
  Q.block<2, 1>(kX, kV) = q_linear * dt2 / 2.0 * along;
  Q.block<1, 2>(kV, kX) = Q.block<2, 1>(kX, kV).transpose();
  Q(kV, kV) = q_linear * dt;
  Q(kYaw, kYaw) = q_angular * dt3 / 3.0;
  Q(kYaw, kW) = Q(kW, kYaw) = q_angular * dt2 / 2.0;
  Q(kW, kW) = q_angular * dt;
  Q(kBias, kBias) = q_bias * dt;
  Q(kScale, kScale) = p.wheel_scale_random_walk * p.wheel_scale_random_walk * dt;
  return Q;
}

void Propagate(const StateVector& x, const StateMatrix& P, double dt, const EkfParameters& parameters,
               StateVector* x_out, StateMatrix* P_out) {
  if (dt <= 0.0) {
    *x_out = x;
    *P_out = P;
    return;
  }
  StateMatrix F;
  PropagateMotion(x, dt, x_out, &F);
  StateMatrix Q = ProcessNoise(x, dt, parameters);
  // The shared fix error decorrelates with the ground travelled: Gauss-Markov over distance, its
  // stationary variance kept by the noise that replaces what decays.
  const double sigma = parameters.shared_fix_error_sigma;
  if (sigma > 0.0) {
    const double travelled = std::abs(x(kV) / (1.0 + x(kScale))) * dt;
    const double keep = std::exp(-travelled / std::max(parameters.shared_fix_error_distance, 1e-3));
    for (int k : {kSharedX, kSharedY}) {
      (*x_out)(k) = keep * x(k);
      F(k, k) = keep;
      Q(k, k) = (1.0 - keep * keep) * sigma * sigma;
    }
  }
  const StateMatrix predicted = F * P * F.transpose() + Q;
  *P_out = 0.5 * (predicted + predicted.transpose());
}

// Measurement model of a pose fix: z = (x + shared_x, y + shared_y, yaw), the yaw innovation wrapped.
Eigen::Vector3d PoseInnovation(const messages::PoseFix& fix, const StateVector& x) {
  return {fix.x - x(kX) - x(kSharedX), fix.y - x(kY) - x(kSharedY), WrapHeading(fix.yaw - x(kYaw))};
}

Eigen::Matrix<double, 3, kN> PoseJacobian() {
  Eigen::Matrix<double, 3, kN> H = Eigen::Matrix<double, 3, kN>::Zero();
  H.leftCols<3>().setIdentity();
  H(0, kSharedX) = 1.0;
  H(1, kSharedY) = 1.0;
  return H;
}

// The shared part of a fix's position variance: the source's stated sigma, but never more than
// half of the fix's smallest position variance, so that its independent rest stays positive
// definite whatever the fix states.
double SharedFixVariance(const messages::PoseFix& fix, double shared_sigma) {
  const double smallest =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(fix.covariance.topLeftCorner<2, 2>(), Eigen::EigenvaluesOnly)
          .eigenvalues()
          .minCoeff();
  return std::min(shared_sigma * shared_sigma, 0.5 * smallest);
}

// What of the fix's covariance is its own (independent of the other fixes).
Eigen::Matrix3d IndependentFixCovariance(const messages::PoseFix& fix, double shared_sigma) {
  Eigen::Matrix3d R = fix.covariance;
  const double shared = SharedFixVariance(fix, shared_sigma);
  R(0, 0) -= shared;
  R(1, 1) -= shared;
  return R;
}

// Linear Kalman update in Joseph form (keeps P symmetric positive semi-definite under rounding).
// Writes nothing and returns false if the innovation covariance is not positive definite or the
// result is not finite.
template <int M>
bool KalmanUpdate(const Eigen::Matrix<double, M, 1>& innovation, const Eigen::Matrix<double, M, kN>& H,
                  const Eigen::Matrix<double, M, M>& R, StateVector* x, StateMatrix* P) {
  const Eigen::Matrix<double, M, M> S = H * (*P) * H.transpose() + R;
  const Eigen::LLT<Eigen::Matrix<double, M, M>> llt(S);
  if (llt.info() != Eigen::Success) return false;
  // K = P H^T S^-1, computed as (S^-1 H P)^T since S and P are symmetric.
  const Eigen::Matrix<double, kN, M> K = llt.solve(H * (*P)).transpose();
  StateVector x_new = *x + K * innovation;
  x_new(kYaw) = WrapHeading(x_new(kYaw));
  const StateMatrix I_KH = StateMatrix::Identity() - K * H;
  StateMatrix P_new = I_KH * (*P) * I_KH.transpose() + K * R * K.transpose();
  P_new = 0.5 * (P_new + P_new.transpose());
  if (!x_new.allFinite() || !P_new.allFinite()) return false;
  *x = x_new;
  *P = P_new;
  return true;
}

}  // namespace

Ekf::Ekf(const EkfParameters& parameters, const robot::DiffDriveGeometry& geometry, int ticks_per_revolution)
    : parameters_(parameters), geometry_(geometry), radians_per_tick_(2.0 * M_PI / ticks_per_revolution) {}

void Ekf::Initialize(double stamp, const Pose2& pose, const Eigen::Matrix3d& pose_covariance) {
  if (!std::isfinite(stamp) || !std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.yaw) ||
      !IsSymmetricPositiveDefinite(pose_covariance)) {
    ++counters_.inputs_dropped;
    return;
  }
  stamp_ = stamp;
  x_.setZero();
  x_.head<3>() << pose.x, pose.y, WrapHeading(pose.yaw);
  P_.setZero();
  P_.topLeftCorner<3, 3>() = pose_covariance;
  P_(kV, kV) = kInitialSpeedSigma * kInitialSpeedSigma;
  P_(kW, kW) = kInitialTurnRateSigma * kInitialTurnRateSigma;
  P_(kBias, kBias) = kInitialGyroBiasSigma * kInitialGyroBiasSigma;
  P_(kScale, kScale) = parameters_.wheel_scale_sigma * parameters_.wheel_scale_sigma;
  P_(kSharedX, kSharedX) = P_(kSharedY, kSharedY) =
      parameters_.shared_fix_error_sigma * parameters_.shared_fix_error_sigma;
  last_ticks_.reset();
  last_imu_stamp_.reset();
  history_.clear();
  rejected_run_.clear();
  initialized_ = true;
}

void Ekf::SetSharedFixError(double sigma, double distance) {
  if (!history_.empty() || last_ticks_ || last_imu_stamp_) {
    throw std::logic_error("Ekf::SetSharedFixError: after the first input");
  }
  parameters_.shared_fix_error_sigma = std::max(sigma, 0.0);
  parameters_.shared_fix_error_distance = distance;
  RestartSharedFixError(parameters_.shared_fix_error_sigma * parameters_.shared_fix_error_sigma);
}

void Ekf::RestartSharedFixError(double variance) {
  x_(kSharedX) = x_(kSharedY) = 0.0;
  for (int k : {kSharedX, kSharedY}) {
    P_.row(k).setZero();
    P_.col(k).setZero();
    P_(k, k) = variance;
  }
}

void Ekf::AddWheelTicks(const messages::WheelTicks& ticks) {
  if (!initialized_ || !std::isfinite(ticks.stamp) || (last_ticks_ && ticks.stamp <= last_ticks_->stamp)) {
    ++counters_.inputs_dropped;
    return;
  }
  if (!last_ticks_) {  // speeds need two readings
    last_ticks_ = ticks;
    return;
  }
  const double dt = ticks.stamp - last_ticks_->stamp;
  const robot::WheelSpeeds wheel_speeds{static_cast<double>(ticks.left - last_ticks_->left) * radians_per_tick_ / dt,
                                        static_cast<double>(ticks.right - last_ticks_->right) * radians_per_tick_ / dt};
  last_ticks_ = ticks;
  const WheelSpeedMeasurement speeds{geometry_.LinearFromWheels(wheel_speeds),
                                     geometry_.AngularFromWheels(wheel_speeds)};
  if (!std::isfinite(speeds.linear) || !std::isfinite(speeds.angular) || !CanApplyAt(ticks.stamp)) {
    ++counters_.inputs_dropped;
    return;
  }
  Insert(ticks.stamp, speeds);
}

void Ekf::AddImu(const messages::ImuSample& imu) {
  // Only the gyro's z rate is fused. The accelerometer would observe v only by integrating specific
  // force, which drifts with its bias and with gravity leaking in on sloped lawns; the wheel speeds
  // observe v directly with a bounded error. (A broken accelerometer value still marks the sample
  // as suspect, so the whole sample is checked.)
  if (!initialized_ || !std::isfinite(imu.stamp) || !imu.angular_velocity.allFinite() ||
      !imu.linear_acceleration.allFinite() || (last_imu_stamp_ && imu.stamp <= *last_imu_stamp_)) {
    ++counters_.inputs_dropped;
    return;
  }
  last_imu_stamp_ = imu.stamp;
  if (!CanApplyAt(imu.stamp)) {
    ++counters_.inputs_dropped;
    return;
  }
  // imu_link is aligned with base_link, so its z rate is the base's yaw rate.
  Insert(imu.stamp, GyroMeasurement{imu.angular_velocity.z()});
}

FixOutcome Ekf::AddPoseFix(const messages::PoseFix& fix) {
  if (!initialized_ || !std::isfinite(fix.stamp) || !std::isfinite(fix.x) || !std::isfinite(fix.y) ||
      !std::isfinite(fix.yaw) || !IsSymmetricPositiveDefinite(fix.covariance) ||
      fix.stamp > stamp_ + parameters_.max_fix_lead) {
    // A fix from the future is a clock error: taking it would move the filter's time ahead and
    // make every sensor input after it look too old.
    ++counters_.inputs_dropped;
    return FixOutcome::kInvalid;
  }
  if (!CanApplyAt(fix.stamp)) {
    ++counters_.fixes_too_old;
    return FixOutcome::kTooOld;
  }

  // Gate against the filter's prediction at the fix's own time.
  StateVector x;
  StateMatrix P;
  StateAt(fix.stamp, &x, &P);
  const Eigen::Vector3d innovation = PoseInnovation(fix, x);
  const Eigen::Matrix<double, 3, kN> H = PoseJacobian();
  const Eigen::Matrix3d S = H * P * H.transpose() + IndependentFixCovariance(fix, parameters_.shared_fix_error_sigma);
  const double mahalanobis2 = innovation.dot(S.llt().solve(innovation));
  if (mahalanobis2 <= parameters_.fix_gate_chi2) {
    Insert(fix.stamp, FixMeasurement{fix, false});
    rejected_run_.clear();
    ++counters_.fixes_accepted;
    return FixOutcome::kAccepted;
  }

  // Rejected. Keep the run of consecutive rejected fixes that agree with this latest one: anything
  // up to the last disagreeing fix starts a different story and is dropped from the run.
  const auto disagrees = [&](const messages::PoseFix& other) {
    return std::hypot(other.x - fix.x, other.y - fix.y) > parameters_.relocalize_consistency;
  };
  const auto last_disagreeing = std::find_if(rejected_run_.rbegin(), rejected_run_.rend(), disagrees);
  rejected_run_.erase(rejected_run_.begin(), last_disagreeing.base());
  rejected_run_.push_back(fix);
  if (static_cast<int>(rejected_run_.size()) >= std::max(1, parameters_.relocalize_after_rejections)) {
    // The source keeps telling the same story: the filter is the one that is lost.
    Insert(fix.stamp, FixMeasurement{fix, true});
    rejected_run_.clear();
    ++counters_.relocalizations;
    return FixOutcome::kRelocalized;
  }
  ++counters_.fixes_rejected;
  return FixOutcome::kRejectedOutlier;
}

PoseEstimate Ekf::Estimate() const {
  PoseEstimate estimate;
  estimate.stamp = stamp_;
  estimate.pose = {x_(kX), x_(kY), x_(kYaw)};
  estimate.linear_velocity = x_(kV) / (1.0 + x_(kScale));  // over the ground
  estimate.angular_velocity = x_(kW);
  estimate.gyro_bias = x_(kBias);
  estimate.wheel_scale = x_(kScale);
  estimate.covariance = P_.topLeftCorner<3, 3>();
  return estimate;
}

bool Ekf::CanApplyAt(double stamp) const {
  if (stamp >= stamp_) return true;
  if (stamp < stamp_ - parameters_.history_seconds) return false;
  const double oldest_restorable = history_.empty() ? stamp_ : history_.front().stamp_before;
  return stamp >= oldest_restorable;
}

void Ekf::StateAt(double stamp, StateVector* x, StateMatrix* P) const {
  // Inputs at the same stamp count as before it.
  const auto later = std::upper_bound(history_.begin(), history_.end(), stamp,
                                      [](double t, const HistoryEntry& entry) { return t < entry.stamp; });
  if (later == history_.end()) {
    Propagate(x_, P_, stamp - stamp_, parameters_, x, P);
  } else {
    Propagate(later->x_before, later->P_before, stamp - later->stamp_before, parameters_, x, P);
  }
}

void Ekf::Insert(double stamp, const Input& input) {
  const auto later = std::upper_bound(history_.begin(), history_.end(), stamp,
                                      [](double t, const HistoryEntry& entry) { return t < entry.stamp; });
  std::vector<HistoryEntry> replay(std::make_move_iterator(later), std::make_move_iterator(history_.end()));
  if (!replay.empty()) {
    stamp_ = replay.front().stamp_before;
    x_ = replay.front().x_before;
    P_ = replay.front().P_before;
    history_.erase(history_.end() - static_cast<std::ptrdiff_t>(replay.size()), history_.end());
  }
  Process(stamp, input);
  for (const HistoryEntry& entry : replay) Process(entry.stamp, entry.input);
  TrimHistory();
}

void Ekf::Process(double stamp, const Input& input) {
  history_.push_back({stamp, input, stamp_, x_, P_});
  Predict(stamp);
  if (!Apply(input) || !x_.allFinite() || !P_.allFinite()) {
    // Never keep a state that is not finite; forget the input instead.
    stamp_ = history_.back().stamp_before;
    x_ = history_.back().x_before;
    P_ = history_.back().P_before;
    history_.pop_back();
    ++counters_.inputs_dropped;
  }
}

void Ekf::Predict(double stamp) {
  if (stamp <= stamp_) return;
  StateVector x;
  StateMatrix P;
  Propagate(x_, P_, stamp - stamp_, parameters_, &x, &P);
  x_ = x;
  P_ = P;
  stamp_ = stamp;
}

bool Ekf::Apply(const Input& input) {
  if (const auto* speeds = std::get_if<WheelSpeedMeasurement>(&input)) return UpdateWheelSpeeds(*speeds);
  if (const auto* gyro = std::get_if<GyroMeasurement>(&input)) return UpdateGyro(gyro->rate);
  const auto& fix = std::get<FixMeasurement>(input);
  if (fix.relocalize) {
    ResetPose(fix.fix);
    return true;
  }
  return UpdatePose(fix.fix);
}

bool Ekf::UpdateWheelSpeeds(const WheelSpeedMeasurement& m) {
  // The wheels measure their own speeds (v, w); the slip state scales v into the ground's motion
  // (PropagateMotion), so only the position fixes observe it - the wheels cannot tell slip from
  // speed. Per wheel, a fixed sigma (encoder quantization over one period) plus a slip fraction of
  // the wheel's speed for the slip's fast part. The faster wheel turns at |v| + |w| * separation /
  // 2; a wheel speed error becomes a turn rate error through 2 / separation.
  const double half_separation = 0.5 * geometry_.wheel_separation;
  const double linear_sigma = parameters_.wheel_speed_sigma + parameters_.wheel_slip_fraction * std::abs(m.linear);
  const double fastest_wheel = std::abs(m.linear) + half_separation * std::abs(m.angular);
  const double angular_sigma =
      (parameters_.wheel_speed_sigma + parameters_.wheel_slip_fraction * fastest_wheel) / half_separation;
  Eigen::Matrix<double, 2, kN> H = Eigen::Matrix<double, 2, kN>::Zero();
  H(0, kV) = 1.0;
  H(1, kW) = 1.0;
  const Eigen::Vector2d innovation(m.linear - x_(kV), m.angular - x_(kW));
  const Eigen::Matrix2d R = Eigen::Vector2d(linear_sigma * linear_sigma, angular_sigma * angular_sigma).asDiagonal();
  return KalmanUpdate<2>(innovation, H, R, &x_, &P_);
}

bool Ekf::UpdateGyro(double rate) {
  // The gyro measures the true rate plus its bias.
  Eigen::Matrix<double, 1, kN> H = Eigen::Matrix<double, 1, kN>::Zero();
  H(0, kW) = 1.0;
  H(0, kBias) = 1.0;
  const Eigen::Matrix<double, 1, 1> innovation(rate - x_(kW) - x_(kBias));
  const Eigen::Matrix<double, 1, 1> R(parameters_.gyro_sigma * parameters_.gyro_sigma);
  return KalmanUpdate<1>(innovation, H, R, &x_, &P_);
}

bool Ekf::UpdatePose(const messages::PoseFix& fix) {
  return KalmanUpdate<3>(PoseInnovation(fix, x_), PoseJacobian(),
                         IndependentFixCovariance(fix, parameters_.shared_fix_error_sigma), &x_, &P_);
}

void Ekf::ResetPose(const messages::PoseFix& fix) {
  // Re-localization: the old pose and its correlations are wrong, so take the fix's pose and
  // covariance as they are, and start the shared fix error afresh; the speeds, the gyro bias and
  // the slip stay.
  x_(kX) = fix.x;
  x_(kY) = fix.y;
  x_(kYaw) = WrapHeading(fix.yaw);
  P_.topRows<3>().setZero();
  P_.leftCols<3>().setZero();
  P_.topLeftCorner<3, 3>() = 0.5 * (fix.covariance + fix.covariance.transpose());
  RestartSharedFixError(SharedFixVariance(fix, parameters_.shared_fix_error_sigma));
}

void Ekf::TrimHistory() {
  // Keep entries so that the state at (filter time - history_seconds) stays restorable: an entry
  // can go once the next one's before-state is at or before that time.
  const double keep_from = stamp_ - parameters_.history_seconds;
  while (history_.size() >= 2 && history_[1].stamp_before <= keep_from) history_.pop_front();
}

}  // namespace trimbot::stack
