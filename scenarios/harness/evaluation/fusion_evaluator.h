#pragma once
// Evaluation of the stack's local fusion against the ground truth, as an observer of the loop:
// for each registration the stack reports, the relative-pose error of the wheel-odometry guess
// and of the registered result (the true relative pose from the ground truth at the two ring
// frames' stamps).
#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "loop/closed_loop.h"

namespace trimbot::scenarios {

struct FusionPairError {
  double time = 0.0;
  std::size_t previous_points = 0, points = 0;
  double odometry_translation_cm = 0.0, odometry_rotation_deg = 0.0;
  double dugma_translation_cm = 0.0, dugma_rotation_deg = 0.0;
  double seconds = 0.0;
};

class FusionEvaluator : public Observer {
 public:
  void Observe(const StepView& step) override;
  const std::vector<FusionPairError>& pairs() const { return pairs_; }
  nlohmann::json ToJson() const;

 private:
  std::map<double, Eigen::Isometry3d> truth_at_frames_;  // ground truth at ring frames
  std::vector<FusionPairError> pairs_;
};

}  // namespace trimbot::scenarios
