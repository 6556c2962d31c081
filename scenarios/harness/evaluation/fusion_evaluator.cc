#include "evaluation/fusion_evaluator.h"

#include "evaluation/pose_errors.h"
#include "evaluation/trial_result.h"

namespace trimbot::scenarios {

void FusionEvaluator::Observe(const StepView& step) {
  if (step.sensors.ring) truth_at_frames_[step.sensors.ring->stamp] = step.truth.T_map_base;
  if (step.telemetry == nullptr || !step.telemetry->registration) return;
  const perception::CloudRegistration& r = *step.telemetry->registration;
  const auto previous = truth_at_frames_.find(r.previous_stamp), current = truth_at_frames_.find(r.stamp);
  if (previous == truth_at_frames_.end() || current == truth_at_frames_.end()) return;
  const Eigen::Isometry3d truth = previous->second.inverse() * current->second;
  FusionPairError e;
  e.time = step.time;
  e.previous_points = r.previous_points;
  e.points = r.points;
  e.odometry_translation_cm = TranslationError(r.odometry_guess, truth) * 100.0;
  e.odometry_rotation_deg = RotationErrorDegrees(r.odometry_guess, truth);
  e.dugma_translation_cm = TranslationError(r.registration.transform, truth) * 100.0;
  e.dugma_rotation_deg = RotationErrorDegrees(r.registration.transform, truth);
  e.seconds = r.seconds;
  pairs_.push_back(e);
  truth_at_frames_.erase(truth_at_frames_.begin(), previous);  // older frames are no longer needed
}

nlohmann::json FusionEvaluator::ToJson() const {
  nlohmann::json pairs = nlohmann::json::array();
  std::vector<double> ot, orot, dt, drot, seconds;
  for (const auto& e : pairs_) {
    pairs.push_back({{"time", e.time},
                     {"points", {e.previous_points, e.points}},
                     {"odometry_translation_cm", e.odometry_translation_cm},
                     {"odometry_rotation_deg", e.odometry_rotation_deg},
                     {"dugma_translation_cm", e.dugma_translation_cm},
                     {"dugma_rotation_deg", e.dugma_rotation_deg},
                     {"seconds", e.seconds}});
    ot.push_back(e.odometry_translation_cm);
    orot.push_back(e.odometry_rotation_deg);
    dt.push_back(e.dugma_translation_cm);
    drot.push_back(e.dugma_rotation_deg);
    seconds.push_back(e.seconds);
  }
  const auto mean = [](const std::vector<double>& v) { return ErrorStats::From(v).mean; };
  return {{"pairs", pairs},
          {"mean",
           {{"odometry_translation_cm", mean(ot)},
            {"odometry_rotation_deg", mean(orot)},
            {"dugma_translation_cm", mean(dt)},
            {"dugma_rotation_deg", mean(drot)},
            {"seconds", mean(seconds)}}}};
}

}  // namespace trimbot::scenarios
