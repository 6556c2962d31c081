#pragma once
// The last metre to a bush by visual servoing: the bush's centre, measured by stereo in each frame
// (perception/bush_estimator.h), is tracked in a local odometry frame (wheel distance, gyro
// heading: GyroOdometry) - a bush does not move, and over a metre that frame drifts by millimetres,
// while the map pose may be off by centimetres - and
// the base is driven until the arm's axis stands at the standoff distance from the centre with the
// bush at the wanted bearing; arrival is confirmed by frames taken standing still. A system with
// explicit inputs (measurements, odometry pose, time), output (base velocity) and state (track,
// mode). It knows nothing of the map: the reference's "visual servoing is not affected by any
// error in the pre-built map".
#include <Eigen/Core>
#include <optional>
#include <string>

#include "trimbot/messages/commands.h"
#include "trimbot/stack/wheel_odometry.h"

namespace trimbot::stack {

struct BushServoParameters {
  double surface_gap = 0.7;                       // m: from the bush's surveyed outline to the arm's axis (the
                                                  // standoff is the bush's radius plus this); stereo sees from
                                                  // 0.5 m, the footprint's front keeps ~0.2 m from the foliage
  double bearing = 0.0;                           // rad: where the bush should stand, seen from the arm's axis
  double distance_tolerance = 0.005;              // m: arrived when both are within these
  double bearing_tolerance = 0.5 * M_PI / 180.0;  // rad
  double turn_first = 3.0 * M_PI / 180.0;         // rad: a bearing error above this is turned away on the spot
  double gain = 1.0;                              // 1/s: speed per metre of distance error
  double turn_gain = 1.5;                         // 1/s: turn rate per radian of bearing error
  double max_speed = 0.08;                        // m/s
  double min_speed = 0.015;                       // m/s: slower than this the base hardly moves
  double max_turn_rate = 0.3;                     // rad/s
  double min_turn_rate = 0.03;                    // rad/s
  double range_sigma = 0.01;                      // m: a frame's centre is good to range_sigma * (range / 1 m)^2
  double memory = 0.7;                            // per frame, the weight kept of what was tracked before: old
                                                  // frames carry the odometry's heading drift since they were taken
  double max_jump = 0.15;                         // m: a frame's centre this far from the track is not the bush
  double first_gate_margin = 0.25;                // m: added for the first frame, gated by the map's belief
  int settle_frames = 2;                          // frames taken standing still that must confirm arrival
  double settle_time = 0.3;                       // s after stopping before a frame counts as standing still
  int max_lost_frames = 8;                        // frames in a row without a usable centre -> give up
  double timeout = 90.0;                          // s for the whole servo
};

class BushServo {
 public:
  enum class Mode { kIdle, kServoing, kSettling, kDone, kFailed };

  // `arm_axis`: the arm's base in base_link (x, y), the point the standoff is measured from.
  BushServo(const BushServoParameters& parameters, const Eigen::Vector2d& arm_axis);

  // The bush to track: believed at `expected_centre` (odometry frame, from the map and the pose
  // estimate), its surveyed outline `outline_radius` from the centre on the side approached (the
  // standoff's surface gap is measured from it). Clears the track if it is far from that belief (a
  // new bush).
  void Expect(const Eigen::Vector2d& expected_centre, double outline_radius);
  // Starts driving at `stamp` (measurements are tracked from Expect on, driving or not).
  void Start(double stamp);
  // A frame's centre of the bush in base_link, with the odometry pose at the frame's stamp.
  // Returns whether the track took it (false: too far from the track). Two frames in a row that
  // agree with each other but not with the track, and are near the map's belief, start it again
  // from them (the track was wrong).
  bool AddMeasurement(double stamp, const Pose2& odometry, const Eigen::Vector2d& centre_base);
  // A frame in which the bush was looked for and not found.
  void AddMiss(double stamp);
  messages::BaseVelocityCommand Update(double stamp, const Pose2& odometry);

  Mode mode() const { return mode_; }
  const std::string& failure() const { return failure_; }
  bool tracking() const { return weight_ > 0.0; }
  // The tracked centre in the odometry frame (the expected one before any measurement).
  Eigen::Vector2d centre() const { return tracking() ? weighted_sum_ / weight_ : expected_; }
  double target_distance() const { return target_distance_; }
  // The tracked centre as the arm sees it from `odometry`: distance (m) and bearing (rad).
  Eigen::Vector2d DistanceBearing(const Pose2& odometry) const;

 private:
  BushServoParameters parameters_;
  Eigen::Vector2d arm_axis_;
  Mode mode_ = Mode::kIdle;
  std::string failure_;
  Eigen::Vector2d expected_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d weighted_sum_ = Eigen::Vector2d::Zero();
  double weight_ = 0.0;
  double target_distance_ = 0.0;
  double start_ = 0.0;
  double stopped_since_ = -1.0;  // s: when the base was last commanded to stand (settling)
  int settle_count_ = 0;
  int lost_ = 0;
  std::optional<Eigen::Vector2d> candidate_;  // the last centre the track refused (odometry frame)
};

const char* ToString(BushServo::Mode mode);

}  // namespace trimbot::stack
