#pragma once
// Planar pose filter of the base: an extended Kalman filter over
//   state (x, y, yaw, v, w, gyro_bias, wheel_scale, shared_fix_error_x, _y) - map-frame pose of
//   base_link, the wheels' body speeds, gyro z bias, the wheels' slip (the base moves over the
//   ground at v / (1 + wheel_scale), the encoders reading (1 + wheel_scale) times the ground's
//   motion), and the position error the fixes share with the fixes taken near them
// that fuses wheel odometry (speeds from encoder counts, 50 Hz) and the IMU gyro (200 Hz) at their
// own rates, and absolute pose fixes that arrive late (stamped in the past: visual localization
// takes ~150 ms, sometimes much more). Late fixes are applied at their own time by rewinding to the
// buffered state before the fix and replaying the buffered sensor inputs after it. Fixes that are
// outliers (Mahalanobis gate) are rejected; a run of consistent rejected fixes means the filter,
// not the source, is wrong, and the filter re-localizes on them.
//
// Why a slip state: slip on grass is biased (the wheels turn more than the ground moves, a few
// percent) and changes over seconds with the surface. As white noise on each 50 Hz speed it averages
// away, the filter believes its odometry to a fraction of a percent, and it becomes over-confident
// between fixes (mean NEES 12.9 against chi-square's 3 on the simulated-fix rectangle; 2.4 with
// the slip state). As a state it is estimated from the fixes, and its random walk keeps the
// along-track uncertainty honest.
//
// Why a shared fix error: a visual fix is computed from map points, and a map built from the robot's
// own log is off by the same few centimetres for every fix taken from the same part of it (its scale
// and its calibration's biases: on the rectangle the fixes sit 1.6 cm to the robot's left, turn after
// turn). Averaged as independent, such fixes made the filter claim a fraction of a centimetre
// while it was 3 cm off (EKF NEES 25 against chi-square's 3). So the part of each fix's covariance
// that the source shares between nearby fixes is a state: a first-order Gauss-Markov process over
// the distance travelled, with that covariance as its stationary one; the fix measures the pose plus
// it, and the rest of the fix covariance is independent noise.
//
// Inputs must come in time order per sensor; the filter's time is the latest input stamp.
// Bad inputs (non-finite values, covariances that are not positive definite, stamps going back)
// are dropped and counted, never propagated into the state.
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>
#include <variant>

#include "trimbot/common/pose2.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/diff_drive.h"

namespace trimbot::stack {

struct EkfParameters {
  // Process noise: white acceleration densities of the constant-velocity model.
  double linear_acceleration_density = 0.5;   // m/s^2/sqrt(Hz)
  double angular_acceleration_density = 1.0;  // rad/s^2/sqrt(Hz)
  double gyro_bias_random_walk = 2.0e-4;      // rad/s^2/sqrt(Hz) (tuned above the sensor's value)
  // Measurement noise.
  double wheel_speed_sigma = 0.02;         // m/s per wheel-derived body speed, plus:
  double wheel_slip_fraction = 0.05;       // sigma grows with speed (grass slips a few percent)
  double wheel_scale_sigma = 0.05;         // prior on the slip state (a few percent)
  double wheel_scale_random_walk = 0.005;  // 1/sqrt(s): how fast the slip changes (surfaces, seconds)
  double gyro_sigma = 0.005;               // rad/s, one gyro sample
  // Pose fixes.
  // Of each fix's position sigma, the part the fix source shares with its other fixes within about
  // shared_fix_error_distance of travel (0: fixes independent). Set by the stack from the source
  // (SetSharedFixError): the visual localizer's covariance floor over its map's extent.
  double shared_fix_error_sigma = 0.0;     // m per axis
  double shared_fix_error_distance = 3.0;  // m
  double fix_gate_chi2 = 11.34;            // 3 dof, 99 %: beyond this a fix is an outlier
  int relocalize_after_rejections = 5;     // consistent rejected fixes in a row -> accept
  double relocalize_consistency = 0.5;     // m: rejected fixes agree if within this of each other
  double history_seconds = 3.0;            // how far back a late fix can be applied
  double max_fix_lead = 0.5;               // s: fixes stamped further ahead of the filter are invalid
};

// Filter output at its current time.
struct PoseEstimate {
  double stamp = 0.0;
  Pose2 pose;
  double linear_velocity = 0.0, angular_velocity = 0.0;
  double gyro_bias = 0.0;
  double wheel_scale = 0.0;                                  // encoder reading / ground motion - 1 (slip)
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // of (x, y, yaw)
};

enum class FixOutcome { kAccepted, kRejectedOutlier, kRelocalized, kTooOld, kInvalid };

struct EkfCounters {
  int fixes_accepted = 0;
  int fixes_rejected = 0;   // outliers
  int relocalizations = 0;  // rejected runs accepted as a re-localization
  int fixes_too_old = 0;    // older than the history buffer
  int inputs_dropped = 0;   // invalid inputs of any kind
};

class Ekf {
 public:
  static constexpr int kStateSize = 9;
  using StateVector = Eigen::Matrix<double, kStateSize, 1>;
  using StateMatrix = Eigen::Matrix<double, kStateSize, kStateSize>;

  Ekf(const EkfParameters& parameters, const robot::DiffDriveGeometry& geometry, int ticks_per_revolution);

  // The fix source's shared error (EkfParameters::shared_fix_error_*), known once the source is
  // (a visual map's, when it is loaded): the shared state restarts at 0 with its stationary
  // variance. Before the first sensor input only (std::logic_error after).
  void SetSharedFixError(double sigma, double distance);

  // Starts the filter at a known pose (the robot's start pose, or the first fix).
  void Initialize(double stamp, const Pose2& pose, const Eigen::Matrix3d& pose_covariance);
  bool initialized() const { return initialized_; }

  void AddWheelTicks(const messages::WheelTicks& ticks);
  void AddImu(const messages::ImuSample& imu);
  FixOutcome AddPoseFix(const messages::PoseFix& fix);

  PoseEstimate Estimate() const;
  const EkfCounters& counters() const { return counters_; }
  const StateVector& state() const { return x_; }
  const StateMatrix& covariance() const { return P_; }

 private:
  // The history holds every input applied (sensor measurements and fixes), each with the filter
  // state just before it, so that an input stamped in the past can be applied at its own time:
  // restore the state before the first later input, apply it, replay the later inputs.
  struct WheelSpeedMeasurement {
    double linear = 0.0, angular = 0.0;  // m/s, rad/s: mean body speeds since the previous ticks
  };
  struct GyroMeasurement {
    double rate = 0.0;  // rad/s about z
  };
  struct FixMeasurement {
    messages::PoseFix fix;
    bool relocalize = false;  // replace the pose instead of fusing it
  };
  using Input = std::variant<WheelSpeedMeasurement, GyroMeasurement, FixMeasurement>;
  struct HistoryEntry {
    double stamp = 0.0;  // of the input
    Input input;
    double stamp_before = 0.0;  // filter time and state just before the input
    StateVector x_before;
    StateMatrix P_before;
  };

  // Whether the state at `stamp` can be reconstructed (not older than the history).
  bool CanApplyAt(double stamp) const;
  // The predicted state at `stamp` (>= the oldest restorable time), without changing the filter.
  void StateAt(double stamp, StateVector* x, StateMatrix* P) const;
  // Applies `input` at `stamp`, rewinding and replaying if it is older than the filter's time.
  // Requires CanApplyAt(stamp).
  void Insert(double stamp, const Input& input);
  // Records, predicts to `stamp` (>= filter time) and applies; reverts if the result is not finite.
  void Process(double stamp, const Input& input);
  void Predict(double stamp);
  bool Apply(const Input& input);
  bool UpdateWheelSpeeds(const WheelSpeedMeasurement& m);
  bool UpdateGyro(double rate);
  bool UpdatePose(const messages::PoseFix& fix);
  void ResetPose(const messages::PoseFix& fix);
  // The shared fix error back to 0 with `variance` per axis, uncorrelated with the rest.
  void RestartSharedFixError(double variance);
  void TrimHistory();

  EkfParameters parameters_;
  robot::DiffDriveGeometry geometry_;
  double radians_per_tick_;
  bool initialized_ = false;
  double stamp_ = 0.0;
  StateVector x_ = StateVector::Zero();
  StateMatrix P_ = StateMatrix::Identity();
  std::optional<messages::WheelTicks> last_ticks_;
  std::optional<double> last_imu_stamp_;
  std::deque<HistoryEntry> history_;
  std::deque<messages::PoseFix> rejected_run_;
  EkfCounters counters_;
};

}  // namespace trimbot::stack
