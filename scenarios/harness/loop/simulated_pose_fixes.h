#pragma once
// TEST FIXTURE, not localization: absolute pose fixes of base_link drawn from the simulator's
// ground truth with the error statistics of the real visual localization (reference deliverable
// D3.4, section 2: ~150 ms processing with a long tail, cm-level errors, occasional gross
// outliers, frames where it does not localize at all). It lives on the evaluation side because it
// reads the ground truth; the stack receives its fixes on its pose-fix input, as it would from a
// separate localization process, when the stack is configured with
// `localization: simulated_pose_fixes`. Use it to tune planning and control; it predicts nothing
// about where visual localization would fail.
#include <cstdint>
#include <deque>
#include <random>
#include <vector>

#include "trimbot/common/random.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {

struct SimulatedPoseFixParameters {
  double availability = 0.85;                   // fraction of frames that localize
  double position_sigma = 0.055;                // m per axis (mean 2D error ~6.9 cm, as in the real trials)
  double yaw_sigma = 0.02;                      // rad
  double latency_median = 0.15;                 // s, log-normal processing time ...
  double latency_log_sigma = 0.35;              // ... with this spread of log(latency)
  double latency_max = 1.5;                     // s
  double outlier_probability = 0.02;            // gross errors (wrong place recognized)
  double outlier_min = 0.5, outlier_max = 3.0;  // m
};

class SimulatedPoseFixes {
 public:
  SimulatedPoseFixes(const SimulatedPoseFixParameters& parameters, std::uint64_t seed);

  // One physics step's ground truth: a ring exposure (cameras not dropped out) may start a fix;
  // fixes whose processing has finished by truth.stamp are appended to `out`, in finishing order.
  void Step(const sim::GroundTruth& truth, std::vector<messages::PoseFix>* out);

  const SimulatedPoseFixParameters& parameters() const { return parameters_; }

 private:
  void Capture(double stamp, double x, double y, double yaw);

  struct Pending {
    double ready = 0.0;
    messages::PoseFix fix;
  };
  SimulatedPoseFixParameters parameters_;
  Rng rng_;
  std::deque<Pending> pending_;
  double busy_until_ = -1.0;  // the pipeline processes one frame at a time
};

}  // namespace trimbot::scenarios
