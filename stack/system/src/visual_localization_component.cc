#include "visual_localization_component.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <utility>

#include <Eigen/Eigenvalues>

namespace trimbot::stack {

VisualLocalizationComponent::VisualLocalizationComponent(const StackParameters& parameters, std::uint64_t seed)
    : parameters_(parameters), latency_rng_(MakeRng(seed, "visual_localization_latency")) {}

void VisualLocalizationComponent::SetLocalizer(std::unique_ptr<visual_localization::VisualLocalizer> localizer) {
  localizer_ = std::move(localizer);
}

bool VisualLocalizationComponent::Due(double stamp, const StackState& /*state*/) const {
  return parameters_.localization == LocalizationSource::kVisual && localizer_ && stamp + 1e-9 >= next_frame_ &&
         stamp >= busy_until_;
}

messages::RingRequest VisualLocalizationComponent::Request(const StackState& /*state*/) const {
  messages::RingRequest request;
  request.cameras = localizer_->cameras();
  request.resolution_scale = parameters_.visual.image_scale;
  return request;
}

void VisualLocalizationComponent::Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) {
  ScopedTimer timer(&telemetry->timings.visual_localization);
  std::optional<Eigen::Vector2d> prior;
  if (state->ekf.initialized()) {
    const Pose2 estimate = state->ekf.Estimate().pose;
    prior = Eigen::Vector2d(estimate.x, estimate.y);
  }
  const auto start = std::chrono::steady_clock::now();
  const visual_localization::LocalizationResult result = localizer_->Localize(frame, prior);
  const double measured = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const VisualLocalizationParameters& v = parameters_.visual;
  const double drawn =
      std::min(v.latency_max, v.latency_median * std::exp(v.latency_log_sigma * StandardNormal(latency_rng_)));
  const double latency = v.measured_latency ? measured : drawn;
  busy_until_ = frame.stamp + latency;  // one frame at a time
  next_frame_ = frame.stamp + 1.0 / v.rate_hz;
  ++telemetry->visual.attempts;
  telemetry->timings.visual_frames.push_back(result.timings);
  attempts_.push_back(
      {frame.stamp, result.failed_stage, result.failure, result.features, result.matches, result.inliers});
  if (!result.success) {
    ++telemetry->visual.failures;
    return;
  }
  ++telemetry->visual.fixes;
  messages::PoseFix fix;
  fix.stamp = frame.stamp;
  const Pose2 planar = ToPose2(result.T_map_base);
  fix.x = planar.x;
  fix.y = planar.y;
  fix.yaw = planar.yaw;
  fix.covariance = result.planar_covariance;
  pending_fixes_.push_back({frame.stamp + latency, fix});
}

void VisualLocalizationComponent::DeliverFixes(double stamp, Ekf* ekf, Telemetry* telemetry) {
  telemetry->visual_fixes.clear();
  for (auto it = pending_fixes_.begin(); it != pending_fixes_.end();) {
    if (it->ready > stamp + 1e-12) {
      ++it;
      continue;
    }
    FixOutcome outcome;
    {
      ScopedTimer timer(&telemetry->timings.ekf);
      outcome = ekf->AddPoseFix(it->fix);
    }
    telemetry->visual_fixes.push_back({it->fix, outcome});
    it = pending_fixes_.erase(it);
  }
}

bool VisualLocalizationComponent::Lost(const Ekf& ekf) const {
  if (parameters_.localization != LocalizationSource::kVisual) return false;
  const Eigen::Matrix2d position = ekf.Estimate().covariance.topLeftCorner<2, 2>();
  const double sigma = std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(position).eigenvalues().maxCoeff());
  return sigma > parameters_.visual.max_position_sigma;
}

}  // namespace trimbot::stack
