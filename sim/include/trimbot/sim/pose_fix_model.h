#pragma once
// Stand-in for the visual localization (Upright-SIFT against a pre-built map) until the stack has
// its own: absolute pose fixes of base_link made from the ground truth with the error statistics
// of the real pipeline (reference deliverable D3.4, section 2: ~150 ms processing with a long
// tail, cm-level errors, occasional gross outliers, frames where it does not localize at all).
// It lives in the simulator because it reads the ground truth; the stack only sees PoseFix
// messages, as it will from the real pipeline.
#include <cstdint>
#include <deque>
#include <random>
#include <vector>

#include "trimbot/common/random.h"
#include "trimbot/messages/sensor_messages.h"

namespace trimbot::sim {

struct PoseFixModelParameters {
  bool enabled = false;
  double availability = 0.85;         // fraction of frames that localize
  double position_sigma = 0.055;      // m per axis (mean 2D error ~6.9 cm, as in the real trials)
  double yaw_sigma = 0.02;            // rad
  double latency_median = 0.15;       // s, log-normal processing time ...
  double latency_log_sigma = 0.35;    // ... with this spread of log(latency)
  double latency_max = 1.5;           // s
  double outlier_probability = 0.02;  // gross errors (wrong place recognized)
  double outlier_min = 0.5, outlier_max = 3.0;  // m
};

class PoseFixModel {
 public:
  PoseFixModel(const PoseFixModelParameters& parameters, std::uint64_t seed);

  // A ring frame captured at `stamp` (one attempt per frame) with the true planar pose: maybe
  // schedules a fix.
  void Capture(double stamp, double x, double y, double yaw);
  // Fixes whose processing has finished by `now`, in the order they finish.
  void Deliver(double now, std::vector<messages::PoseFix>* out);

  const PoseFixModelParameters& parameters() const { return parameters_; }

 private:
  struct Pending {
    double ready = 0.0;
    messages::PoseFix fix;
  };
  PoseFixModelParameters parameters_;
  Rng rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  std::deque<Pending> pending_;
  double busy_until_ = -1.0;   // the pipeline processes one frame at a time
};

}  // namespace trimbot::sim
