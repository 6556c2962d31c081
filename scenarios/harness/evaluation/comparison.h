#pragma once
// Regression check of a candidate batch against a baseline batch of the same scenario (their
// summary.json): per metric the delta with a 95 % interval, a one-sided test in each direction,
// and a verdict - regressed / improved / no evidence. Trials are the unit: success counts are
// compared with Fisher's exact test, per-trial values (collisions, mean EKF errors, mission time,
// and with localization fixes their mean error and the localization rate, where lower is worse) with
// the Mann-Whitney U test. The level is split over the metrics (Bonferroni), so a re-run with
// other seeds is flagged with probability at most `alpha` in all.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "evaluation/statistics.h"

namespace trimbot::scenarios {

struct MetricComparison {
  std::string metric;
  std::string unit;
  std::string test;
  double baseline = 0.0, candidate = 0.0, delta = 0.0;  // means (rates for success_rate)
  Interval delta_interval;                              // 95 %
  double p_worse = 1.0, p_better = 1.0;                 // one-sided p-values
  std::string verdict = "no evidence";                  // regressed | improved | no evidence
};

struct DetectableDrop {
  double from = 1.0, to = 0.9;  // success rates
  int trials_needed = -1;       // per side, for 80 % power at the per-metric level
  double power_now = 0.0;       // with the candidate's trial count
};

struct Comparison {
  std::string scenario;
  int baseline_trials = 0, candidate_trials = 0;
  double alpha = 0.05, alpha_per_metric = 0.05;
  std::vector<MetricComparison> metrics;
  std::vector<DetectableDrop> power;
  bool regressed = false;
};

// Throws InputError naming the files when the two are not batches of the same scenario.
Comparison CompareBatches(const nlohmann::json& baseline, const std::string& baseline_file,
                          const nlohmann::json& candidate, const std::string& candidate_file, double alpha = 0.05);

// A batch's metrics with 95 % intervals: success_rate (Wilson) and the per-trial metrics above
// (bootstrap of the mean over trials; value NaN when no trial has one).
struct MetricEstimate {
  std::string metric, unit;
  double value = 0.0;
  Interval interval;
  int n = 0;  // trials it rests on
};
std::vector<MetricEstimate> BatchEstimates(const nlohmann::json& summary);

nlohmann::json ToJson(const Comparison& comparison);
std::string ToMarkdown(const Comparison& comparison);
std::string ToJunitXml(const Comparison& comparison);

}  // namespace trimbot::scenarios
