#include "loop/simulated_pose_fixes.h"

#include <algorithm>
#include <cmath>

#include "trimbot/common/pose2.h"

namespace trimbot::scenarios {

SimulatedPoseFixes::SimulatedPoseFixes(const SimulatedPoseFixParameters& parameters, std::uint64_t seed)
    : parameters_(parameters), rng_(MakeRng(seed, "pose_fixes")) {}

bool SimulatedPoseFixes::InOutage(double stamp, double u) {
  const double outage_share = 1.0 - parameters_.availability;
  // Exact transition of the two-state process over the time since the last frame: it relaxes to
  // the stationary share at rate (1/duration) / availability (the sum of both switching rates).
  double p_outage = outage_share;
  if (outage_state_stamp_ >= 0.0 && parameters_.outage_mean_duration > 0.0 && parameters_.availability > 0.0) {
    const double rate = 1.0 / (parameters_.outage_mean_duration * parameters_.availability);
    p_outage += ((in_outage_ ? 1.0 : 0.0) - outage_share) * std::exp(-rate * (stamp - outage_state_stamp_));
  }
  in_outage_ = u < p_outage;
  outage_state_stamp_ = stamp;
  return in_outage_;
}

void SimulatedPoseFixes::Capture(double stamp, double x, double y, double yaw) {
  // Every draw happens for every frame, so one parameter change does not reshuffle the others.
  const double u_available = UniformUnit(rng_);
  const double u_outlier = UniformUnit(rng_);
  const double n_x = StandardNormal(rng_), n_y = StandardNormal(rng_), n_yaw = StandardNormal(rng_),
               n_latency = StandardNormal(rng_);
  const double outlier_distance =
      parameters_.outlier_min + (parameters_.outlier_max - parameters_.outlier_min) * UniformUnit(rng_);
  const double outlier_direction = 2.0 * M_PI * UniformUnit(rng_);

  const bool in_outage = InOutage(stamp, u_available);  // the outage process runs whether or not a frame is processed

  if (stamp < busy_until_) return;  // still processing the previous frame
  const double latency = std::min(parameters_.latency_max,
                                  parameters_.latency_median * std::exp(parameters_.latency_log_sigma * n_latency));
  busy_until_ = stamp + latency;
  if (in_outage) return;  // not localized in this frame

  messages::PoseFix fix;
  fix.stamp = stamp;
  fix.x = x + parameters_.position_sigma * n_x;
  fix.y = y + parameters_.position_sigma * n_y;
  fix.yaw = WrapAngle(yaw + parameters_.yaw_sigma * n_yaw);
  if (u_outlier < parameters_.outlier_probability) {
    fix.x += outlier_distance * std::cos(outlier_direction);
    fix.y += outlier_distance * std::sin(outlier_direction);
  }
  // What the pipeline reports about itself: its nominal accuracy.
  fix.covariance = Eigen::Vector3d(parameters_.position_sigma * parameters_.position_sigma,
                                   parameters_.position_sigma * parameters_.position_sigma,
                                   parameters_.yaw_sigma * parameters_.yaw_sigma)
                       .asDiagonal();
  pending_.push_back({stamp + latency, fix});
}

void SimulatedPoseFixes::Step(const sim::GroundTruth& truth, std::vector<messages::PoseFix>* out) {
  if (truth.ring_exposed) {
    const Eigen::Vector3d x_axis = truth.T_map_base.linear().col(0);
    Capture(truth.stamp, truth.T_map_base.translation().x(), truth.T_map_base.translation().y(),
            std::atan2(x_axis.y(), x_axis.x()));
  }
  while (!pending_.empty() && pending_.front().ready <= truth.stamp) {
    out->push_back(pending_.front().fix);
    pending_.pop_front();
  }
}

}  // namespace trimbot::scenarios
