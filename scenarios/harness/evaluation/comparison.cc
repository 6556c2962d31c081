#include "evaluation/comparison.h"

#include <cmath>
#include <functional>
#include <iomanip>
#include <numeric>
#include <optional>
#include <sstream>
#include <tuple>

#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {
namespace {

using nlohmann::json;

// Mean of one estimate's samples in one trial (nullopt when it has none).
std::optional<double> TrialMean(const json& trial, const std::string& estimate, const std::string& field) {
  if (!trial.contains("estimates")) return std::nullopt;
  for (const auto& e : trial["estimates"]) {
    if (e.value("name", "") != estimate || !e.contains(field) || e[field].empty()) continue;
    const auto samples = e[field].get<std::vector<double>>();
    return Mean(samples);
  }
  return std::nullopt;
}

// Per-trial values of a metric; trials without a value are left out.
using Extractor = std::function<std::optional<double>(const json&)>;
std::vector<double> PerTrial(const json& summary, const Extractor& extract) {
  std::vector<double> values;
  for (const auto& trial : summary["trials"]) {
    if (const auto v = extract(trial)) values.push_back(*v);
  }
  return values;
}

MetricComparison CompareValues(const std::string& metric, const std::string& unit, bool higher_is_worse,
                               const std::vector<double>& a, const std::vector<double>& b) {
  MetricComparison m;
  m.metric = metric;
  m.unit = unit;
  m.test = "Mann-Whitney U, one-sided, per-trial values";
  m.baseline = Mean(a);
  m.candidate = Mean(b);
  m.delta = m.candidate - m.baseline;
  m.delta_interval = BootstrapDifferenceInterval(a, b);
  m.p_worse = higher_is_worse ? MannWhitneyGreaterP(a, b) : MannWhitneyGreaterP(b, a);
  m.p_better = higher_is_worse ? MannWhitneyGreaterP(b, a) : MannWhitneyGreaterP(a, b);
  return m;
}

struct PerTrialMetric {
  std::string name, unit;
  Extractor extract;
  bool higher_is_worse = true;
};

// A visual-localization share of a trial (nullopt without visual localization).
std::optional<double> VisualShare(const json& t, const char* key) {
  if (!t.contains(key) || t[key].get<double>() < 0.0) return std::nullopt;
  return t[key].get<double>();
}

const std::vector<PerTrialMetric>& PerTrialMetricTable() {
  static const std::vector<PerTrialMetric> table = {
      {"collisions_per_trial", "", [](const json& t) { return std::optional<double>(t.value("collisions", 0)); }},
      {"ekf_position_error_m", "m", [](const json& t) { return TrialMean(t, "ekf", "position_m"); }},
      {"ekf_heading_error_deg", "deg", [](const json& t) { return TrialMean(t, "ekf", "heading_deg"); }},
      {"trial_seconds", "s", [](const json& t) { return std::optional<double>(t.value("simulated_seconds", 0.0)); }},
      // The stack's own localization (trials with fixes only): what the robot's Tables 2 and 3 report.
      {"pose_fix_position_error_m", "m", [](const json& t) { return TrialMean(t, "pose_fixes", "position_m"); }},
      {"localization_rate", "", [](const json& t) { return VisualShare(t, "localization_rate"); }, false},
  };
  return table;
}

int Successes(const json& summary) {
  int successes = 0;
  for (const auto& trial : summary["trials"]) successes += trial.value("success", false) ? 1 : 0;
  return successes;
}

MetricComparison CompareSuccess(const json& baseline, const json& candidate) {
  const int na = baseline.value("trials_planned", 0), nb = candidate.value("trials_planned", 0);
  const int sa = Successes(baseline), sb = Successes(candidate);
  MetricComparison m;
  m.metric = "success_rate";
  m.test = "Fisher exact, one-sided";
  m.baseline = na > 0 ? static_cast<double>(sa) / na : 0.0;
  m.candidate = nb > 0 ? static_cast<double>(sb) / nb : 0.0;
  m.delta = m.candidate - m.baseline;
  // Newcombe's interval of a difference of two proportions from the Wilson intervals.
  const Interval wa = WilsonInterval(sa, na), wb = WilsonInterval(sb, nb);
  m.delta_interval = {m.delta - std::sqrt(std::pow(m.candidate - wb.low, 2) + std::pow(wa.high - m.baseline, 2)),
                      m.delta + std::sqrt(std::pow(wb.high - m.candidate, 2) + std::pow(m.baseline - wa.low, 2))};
  m.p_worse = FisherLowerP(sa, na, sb, nb);
  m.p_better = FisherLowerP(sb, nb, sa, na);
  return m;
}

}  // namespace

Comparison CompareBatches(const json& baseline, const std::string& baseline_file, const json& candidate,
                          const std::string& candidate_file, double alpha) {
  for (const auto& [summary, file] : {std::pair{&baseline, &baseline_file}, {&candidate, &candidate_file}}) {
    if (!summary->contains("scenario") || !summary->contains("trials") || !(*summary)["trials"].is_array()) {
      throw InputError(*file, "not a batch summary (summary.json of `trimbot run`)");
    }
  }
  if (baseline["scenario"] != candidate["scenario"]) {
    throw InputError(candidate_file, "is a batch of scenario '" + candidate["scenario"].get<std::string>() +
                                         "', the baseline " + baseline_file + " of '" +
                                         baseline["scenario"].get<std::string>() + "'");
  }
  Comparison c;
  c.scenario = baseline["scenario"].get<std::string>();
  c.baseline_trials = baseline.value("trials_planned", 0);
  c.candidate_trials = candidate.value("trials_planned", 0);
  c.alpha = alpha;
  c.metrics.push_back(CompareSuccess(baseline, candidate));
  for (const auto& metric : PerTrialMetricTable()) {
    const auto a = PerTrial(baseline, metric.extract), b = PerTrial(candidate, metric.extract);
    if (!a.empty() && !b.empty())
      c.metrics.push_back(CompareValues(metric.name, metric.unit, metric.higher_is_worse, a, b));
  }
  c.alpha_per_metric = alpha / static_cast<double>(c.metrics.size());
  for (auto& m : c.metrics) {
    if (m.p_worse < c.alpha_per_metric)
      m.verdict = "regressed";
    else if (m.p_better < c.alpha_per_metric)
      m.verdict = "improved";
    c.regressed = c.regressed || m.verdict == "regressed";
  }
  const double from = c.metrics.front().baseline;
  for (double drop : {0.1, 0.2, 0.3, 0.5}) {
    if (from - drop < 0.0) continue;
    DetectableDrop d{from, from - drop, TrialsToDetect(from, from - drop, c.alpha_per_metric),
                     FisherPower(from, from - drop, std::max(1, c.candidate_trials), c.alpha_per_metric)};
    c.power.push_back(d);
  }
  return c;
}

std::vector<MetricEstimate> BatchEstimates(const json& summary) {
  std::vector<MetricEstimate> estimates;
  const int n = summary.value("trials_planned", 0), successes = Successes(summary);
  estimates.push_back(
      {"success_rate", "", n > 0 ? static_cast<double>(successes) / n : 0.0, WilsonInterval(successes, n), n});
  for (const auto& metric : PerTrialMetricTable()) {
    const auto values = PerTrial(summary, metric.extract);
    const double mean = values.empty() ? std::nan("") : Mean(values);
    estimates.push_back(
        {metric.name, metric.unit, mean, BootstrapMeanInterval(values), static_cast<int>(values.size())});
  }
  return estimates;
}

json ToJson(const Comparison& c) {
  json metrics = json::array();
  for (const auto& m : c.metrics) {
    metrics.push_back({{"metric", m.metric},
                       {"unit", m.unit},
                       {"test", m.test},
                       {"baseline", m.baseline},
                       {"candidate", m.candidate},
                       {"delta", m.delta},
                       {"delta_95", {m.delta_interval.low, m.delta_interval.high}},
                       {"p_worse", m.p_worse},
                       {"p_better", m.p_better},
                       {"verdict", m.verdict}});
  }
  json power = json::array();
  for (const auto& d : c.power) {
    power.push_back({{"success_rate_from", d.from},
                     {"success_rate_to", d.to},
                     {"trials_needed", d.trials_needed},
                     {"power_with_these_trials", d.power_now}});
  }
  return {{"scenario", c.scenario},
          {"baseline_trials", c.baseline_trials},
          {"candidate_trials", c.candidate_trials},
          {"alpha", c.alpha},
          {"alpha_per_metric", c.alpha_per_metric},
          {"metrics", metrics},
          {"power", power},
          {"verdict", c.regressed ? "regressed" : "no regression"}};
}

std::string ToMarkdown(const Comparison& c) {
  std::ostringstream md;
  md << std::setprecision(4);
  md << "### " << c.scenario << ": " << (c.regressed ? "REGRESSED" : "no regression") << "\n\n"
     << "Baseline " << c.baseline_trials << " trials, candidate " << c.candidate_trials
     << " trials; one-sided tests at " << c.alpha << " split over " << c.metrics.size() << " metrics ("
     << c.alpha_per_metric << " each).\n\n"
     << "| metric | baseline | candidate | delta (95 % interval) | p worse | p better | verdict |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (const auto& m : c.metrics) {
    md << "| " << m.metric << (m.unit.empty() ? "" : " (" + m.unit + ")") << " | " << m.baseline << " | " << m.candidate
       << " | " << m.delta << " (" << m.delta_interval.low << ", " << m.delta_interval.high << ") | " << m.p_worse
       << " | " << m.p_better << " | " << m.verdict << " |\n";
  }
  md << "\nTrials per side to detect a drop of the success rate (80 % power):";
  for (const auto& d : c.power) {
    md << " " << d.from << " -> " << d.to << ": "
       << (d.trials_needed < 0 ? std::string(">200") : std::to_string(d.trials_needed)) << " (power now "
       << std::setprecision(2) << d.power_now << std::setprecision(4) << ");";
  }
  md << "\n";
  return md.str();
}

std::string ToJunitXml(const Comparison& c) {
  std::ostringstream xml;
  int failures = 0;
  for (const auto& m : c.metrics) failures += m.verdict == "regressed" ? 1 : 0;
  xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites>\n  <testsuite name=\"compare " << c.scenario
      << "\" tests=\"" << c.metrics.size() << "\" failures=\"" << failures << "\" errors=\"0\">\n";
  for (const auto& m : c.metrics) {
    xml << "    <testcase classname=\"compare." << c.scenario << "\" name=\"" << m.metric << "\"";
    if (m.verdict == "regressed") {
      xml << ">\n      <failure message=\"" << m.metric << " regressed: baseline " << m.baseline << ", candidate "
          << m.candidate << ", p = " << m.p_worse << "\"/>\n    </testcase>\n";
    } else {
      xml << "/>\n";
    }
  }
  xml << "  </testsuite>\n</testsuites>\n";
  return xml.str();
}

}  // namespace trimbot::scenarios
