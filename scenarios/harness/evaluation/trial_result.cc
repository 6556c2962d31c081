#include "evaluation/trial_result.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace trimbot::scenarios {

ErrorStats ErrorStats::From(std::vector<double> samples) {
  ErrorStats stats;
  if (samples.empty()) return stats;
  stats.count = static_cast<int>(samples.size());
  std::sort(samples.begin(), samples.end());
  double sum = 0.0, sum_of_squares = 0.0;
  for (const double s : samples) {
    sum += s;
    sum_of_squares += s * s;
  }
  const std::size_t n = samples.size();
  stats.mean = sum / n;
  stats.median = n % 2 == 1 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
  stats.rmse = std::sqrt(sum_of_squares / n);
  stats.max = samples.back();
  return stats;
}

void to_json(nlohmann::json& j, const ErrorStats& s) {
  j = {{"count", s.count}, {"mean", s.mean}, {"median", s.median}, {"rmse", s.rmse}, {"max", s.max}};
}

void to_json(nlohmann::json& j, const EstimateErrors& e) {
  // The summaries are for people and scripts reading the file; only the samples are read back.
  j = {{"name", e.name},
       {"position_m", e.position_m},
       {"heading_deg", e.heading_deg},
       {"position_stats_m", e.position()},
       {"heading_stats_deg", e.heading()}};
  if (!e.nees.empty()) j["nees"] = e.nees;
}

void from_json(const nlohmann::json& j, EstimateErrors& e) {
  j.at("name").get_to(e.name);
  j.at("position_m").get_to(e.position_m);
  j.at("heading_deg").get_to(e.heading_deg);
  if (j.contains("nees")) j.at("nees").get_to(e.nees);
}

void to_json(nlohmann::json& j, const GoalResult& g) {
  j = {{"x", g.x},
       {"y", g.y},
       {"reached", g.reached},
       {"arrival_time", g.arrival_time},
       {"final_error_m", g.final_error_m},
       {"adjusted_by_m", g.adjusted_by_m},
       {"used_x", g.used_x},
       {"used_y", g.used_y},
       {"reached_as_asked", g.reached_as_asked}};
  if (g.yaw_deg) j["yaw_deg"] = *g.yaw_deg;
  if (g.final_heading_error_deg) j["final_heading_error_deg"] = *g.final_heading_error_deg;
  if (g.bush != 0) {
    j["bush"] = g.bush;
    j["bush_distance_error_m"] = g.bush_distance_error_m;
    j["bush_bearing_error_deg"] = g.bush_bearing_error_deg;
    j["bush_estimate_distance_error_m"] = g.bush_estimate_distance_error_m;
    j["bush_estimate_bearing_error_deg"] = g.bush_estimate_bearing_error_deg;
  }
}

void from_json(const nlohmann::json& j, GoalResult& g) {
  j.at("x").get_to(g.x);
  j.at("y").get_to(g.y);
  j.at("reached").get_to(g.reached);
  j.at("arrival_time").get_to(g.arrival_time);
  j.at("final_error_m").get_to(g.final_error_m);
  g.adjusted_by_m = j.value("adjusted_by_m", 0.0);  // results written before goals could move
  g.used_x = j.value("used_x", g.x);
  g.used_y = j.value("used_y", g.y);
  g.reached_as_asked = j.value("reached_as_asked", g.reached && g.adjusted_by_m == 0.0);
  if (j.contains("yaw_deg")) g.yaw_deg = j.at("yaw_deg").get<double>();
  if (j.contains("final_heading_error_deg")) g.final_heading_error_deg = j.at("final_heading_error_deg").get<double>();
  g.bush = j.value("bush", 0);
  g.bush_distance_error_m = j.value("bush_distance_error_m", 0.0);
  g.bush_bearing_error_deg = j.value("bush_bearing_error_deg", 0.0);
  g.bush_estimate_distance_error_m = j.value("bush_estimate_distance_error_m", 0.0);
  g.bush_estimate_bearing_error_deg = j.value("bush_estimate_bearing_error_deg", 0.0);
}

void to_json(nlohmann::json& j, const BushFrame& f) {
  j = {{"t", f.t},
       {"goal", f.goal},
       {"true_distance_m", f.true_distance_m},
       {"true_bearing_deg", f.true_bearing_deg},
       {"found", f.found},
       {"distance_error_m", f.distance_error_m},
       {"bearing_error_deg", f.bearing_error_deg}};
}

void from_json(const nlohmann::json& j, BushFrame& f) {
  j.at("t").get_to(f.t);
  j.at("goal").get_to(f.goal);
  j.at("true_distance_m").get_to(f.true_distance_m);
  j.at("true_bearing_deg").get_to(f.true_bearing_deg);
  j.at("found").get_to(f.found);
  j.at("distance_error_m").get_to(f.distance_error_m);
  j.at("bearing_error_deg").get_to(f.bearing_error_deg);
}

void to_json(nlohmann::json& j, const TrialResult& t) {
  j = {{"index", t.index},
       {"seed", t.seed},
       {"status", t.status},
       {"message", t.message},
       {"success", t.success},
       {"goals", t.goals},
       {"simulated_seconds", t.simulated_seconds},
       {"path_length_m", t.path_length_m},
       {"collisions", t.collisions},
       {"contact_seconds", t.contact_seconds},
       {"replans", t.replans},
       {"recoveries", t.recoveries},
       {"fixes_accepted", t.fixes_accepted},
       {"fixes_rejected", t.fixes_rejected},
       {"relocalizations", t.relocalizations},
       {"localization_rate", t.localization_rate},
       {"visual_frames_attempted", t.visual_frames_attempted},
       {"faults", t.faults},
       {"estimates", t.estimates}};
  if (t.min_clearance_m) j["min_clearance_m"] = *t.min_clearance_m;
  if (t.visual_frames_attempted > 0) {
    j["visual_frame_outcomes"] = t.visual_frame_outcomes;
    j["localization_stopped_updates"] = t.localization_stopped_updates;
  }
  if (!t.bush_frames.empty()) j["bush_frames"] = t.bush_frames;
  if (!t.arm_goals.empty()) {
    j["arm_goals"] = t.arm_goals;
    j["arm_contacts"] = t.arm_contacts;
  }
  if (!t.trims.empty()) j["trims"] = t.trims;
}

void from_json(const nlohmann::json& j, TrialResult& t) {
  j.at("index").get_to(t.index);
  j.at("seed").get_to(t.seed);
  j.at("status").get_to(t.status);
  j.at("message").get_to(t.message);
  j.at("success").get_to(t.success);
  j.at("goals").get_to(t.goals);
  j.at("simulated_seconds").get_to(t.simulated_seconds);
  j.at("path_length_m").get_to(t.path_length_m);
  j.at("collisions").get_to(t.collisions);
  j.at("contact_seconds").get_to(t.contact_seconds);
  j.at("replans").get_to(t.replans);
  j.at("recoveries").get_to(t.recoveries);
  j.at("fixes_accepted").get_to(t.fixes_accepted);
  j.at("fixes_rejected").get_to(t.fixes_rejected);
  j.at("relocalizations").get_to(t.relocalizations);
  t.localization_rate = j.value("localization_rate", -1.0);
  t.visual_frames_attempted = j.value("visual_frames_attempted", 0);
  if (j.contains("visual_frame_outcomes")) j.at("visual_frame_outcomes").get_to(t.visual_frame_outcomes);
  t.localization_stopped_updates = j.value("localization_stopped_updates", 0);
  j.at("faults").get_to(t.faults);
  j.at("estimates").get_to(t.estimates);
  if (j.contains("min_clearance_m")) t.min_clearance_m = j.at("min_clearance_m").get<double>();
  if (j.contains("bush_frames")) j.at("bush_frames").get_to(t.bush_frames);
  if (j.contains("arm_goals")) {
    j.at("arm_goals").get_to(t.arm_goals);
    j.at("arm_contacts").get_to(t.arm_contacts);
  }
  if (j.contains("trims")) j.at("trims").get_to(t.trims);
}

void to_json(nlohmann::json& j, const CriterionResult& c) {
  j = {
      {"name", c.name}, {"comparison", c.comparison}, {"expected", c.expected}, {"actual", c.actual}, {"pass", c.pass}};
}

void to_json(nlohmann::json& j, const BatchSummary& b) {
  j = {{"scenario", b.scenario},
       {"scenario_file", b.scenario_file},
       {"overrides", b.overrides},
       {"seed", b.seed},
       {"trials_planned", b.trials_planned},
       {"pass", b.pass},
       {"criteria", b.criteria},
       {"metrics", b.metrics},
       {"trials", b.trials}};
}

namespace {

// Metrics of the bush goals and of the frames at 1-3 m (see ComputeBatchMetrics).
void AddBushMetrics(const std::vector<TrialResult>& trials, nlohmann::json& metrics) {
  std::vector<double> distance, bearing, estimate_distance, estimate_bearing;
  for (const TrialResult& trial : trials) {
    for (const GoalResult& goal : trial.goals) {
      if (goal.bush == 0 || goal.arrival_time < 0.0) continue;
      distance.push_back(std::abs(goal.bush_distance_error_m));
      bearing.push_back(std::abs(goal.bush_bearing_error_deg));
      estimate_distance.push_back(std::abs(goal.bush_estimate_distance_error_m));
      estimate_bearing.push_back(std::abs(goal.bush_estimate_bearing_error_deg));
    }
  }
  const auto put = [&](const std::string& name, const std::vector<double>& samples) {
    const ErrorStats stats = ErrorStats::From(samples);
    metrics[name + "_mean"] = stats.mean;
    metrics[name + "_max"] = stats.max;
  };
  if (!distance.empty()) {
    metrics["bush_goals"] = static_cast<int>(distance.size());  // arrived at
    put("bush_distance_error", distance);
    put("bush_bearing_error", bearing);
    put("bush_estimate_distance_error", estimate_distance);
    put("bush_estimate_bearing_error", estimate_bearing);
  }
  std::vector<double> frame_distance, frame_bearing;
  int frames = 0, within = 0;
  for (const TrialResult& trial : trials) {
    for (const BushFrame& frame : trial.bush_frames) {
      if (frame.true_distance_m < 1.0 || frame.true_distance_m > 3.0) continue;
      ++frames;
      if (!frame.found) continue;
      frame_distance.push_back(std::abs(frame.distance_error_m));
      frame_bearing.push_back(std::abs(frame.bearing_error_deg));
      within += std::abs(frame.distance_error_m) <= 0.05 && std::abs(frame.bearing_error_deg) <= 3.0 ? 1 : 0;
    }
  }
  if (frames > 0) {
    metrics["bush_frames_1_3m"] = frames;
    metrics["bush_frame_found_rate"] = static_cast<double>(frame_distance.size()) / frames;
    metrics["bush_frame_within_rate"] = static_cast<double>(within) / frames;
    if (!frame_distance.empty()) {
      put("bush_frame_distance_error", frame_distance);
      put("bush_frame_bearing_error", frame_bearing);
    }
  }
}

// Metrics of arm_reach goals (see ComputeBatchMetrics).
void AddArmMetrics(const std::vector<TrialResult>& trials, nlohmann::json& metrics) {
  std::vector<double> position, orientation, path, cutter_path;
  int goals = 0, reached = 0, contacts = 0;
  double tracking = 0.0;
  std::optional<double> clearance;
  for (const TrialResult& trial : trials) {
    contacts += trial.arm_contacts;
    for (const ArmGoalOutcome& goal : trial.arm_goals) {
      ++goals;
      reached += goal.reached ? 1 : 0;
      tracking = std::max(tracking, goal.tracking_error_max_rad);
      if (goal.min_clearance_m >= 0.0)
        clearance = std::min(clearance.value_or(goal.min_clearance_m), goal.min_clearance_m);
      if (!goal.stack_reached) continue;
      position.push_back(goal.position_error_m);
      orientation.push_back(goal.orientation_error_deg);
      path.push_back(goal.path_length_rad);
      cutter_path.push_back(goal.cutter_path_length_m);
    }
  }
  if (goals == 0) return;
  metrics["arm_goals"] = goals;
  metrics["arm_success_rate"] = static_cast<double>(reached) / goals;
  metrics["arm_contacts"] = contacts;
  metrics["arm_tracking_error_max_rad"] = tracking;
  if (clearance) metrics["arm_min_clearance_m"] = *clearance;
  if (position.empty()) return;
  const ErrorStats p = ErrorStats::From(position), o = ErrorStats::From(orientation);
  metrics["arm_position_error_mean_m"] = p.mean;
  metrics["arm_position_error_max_m"] = p.max;
  metrics["arm_orientation_error_mean_deg"] = o.mean;
  metrics["arm_orientation_error_max_deg"] = o.max;
  metrics["arm_path_length_mean_rad"] = ErrorStats::From(path).mean;
  metrics["arm_cutter_path_length_mean_m"] = ErrorStats::From(cutter_path).mean;
}

// Metrics of trim goals (see ComputeBatchMetrics).
void AddTrimMetrics(const std::vector<TrialResult>& trials, nlohmann::json& metrics) {
  std::vector<double> before, after, upper_before, upper_after, overcut, fit, cutting;
  int trims = 0, succeeded = 0, contacts = 0, touches = 0;
  for (const TrialResult& trial : trials) {
    for (const TrimOutcome& trim : trial.trims) {
      ++trims;
      succeeded += trim.success ? 1 : 0;
      contacts += trim.arm_contacts;
      touches += trim.foliage_touches;
      before.push_back(trim.within_2cm_before);
      after.push_back(trim.within_2cm_after);
      upper_before.push_back(trim.within_2cm_upper_before);
      upper_after.push_back(trim.within_2cm_upper_after);
      overcut.push_back(trim.overcut_share);
      if (trim.fit_centre_error_m >= 0.0) fit.push_back(trim.fit_centre_error_m);
      if (trim.cut) cutting.push_back(trim.cutting_seconds);
    }
  }
  if (trims == 0) return;
  metrics["trim_goals"] = trims;
  metrics["trim_success_rate"] = static_cast<double>(succeeded) / trims;
  metrics["trim_arm_contacts"] = contacts;
  metrics["trim_foliage_touches"] = touches;
  metrics["trim_within_2cm_before_mean"] = ErrorStats::From(before).mean;
  metrics["trim_within_2cm_after_mean"] = ErrorStats::From(after).mean;
  metrics["trim_within_2cm_after_min"] = *std::min_element(after.begin(), after.end());
  metrics["trim_within_2cm_upper_before_mean"] = ErrorStats::From(upper_before).mean;
  metrics["trim_within_2cm_upper_after_mean"] = ErrorStats::From(upper_after).mean;
  metrics["trim_overcut_mean"] = ErrorStats::From(overcut).mean;
  metrics["trim_overcut_max"] = ErrorStats::From(overcut).max;
  if (!fit.empty()) metrics["trim_fit_centre_error_max_m"] = ErrorStats::From(fit).max;
  if (!cutting.empty()) metrics["trim_cutting_seconds_mean"] = ErrorStats::From(cutting).mean;
}

// Localization: the localization rate, the visual localizer's per-frame success and rate, and
// each estimate's errors (and the EKF's NEES) over the samples pooled from every trial.
void AddLocalizationMetrics(const std::vector<TrialResult>& trials, nlohmann::json& metrics) {
  std::vector<double> localization_rates;
  int visual_frames = 0, visual_frames_fixed = 0;
  double visual_seconds = 0.0;
  std::vector<std::string> estimate_names;  // in order of first appearance
  std::map<std::string, std::vector<double>> pooled_position_m, pooled_heading_deg, pooled_nees;
  for (const TrialResult& trial : trials) {
    if (trial.localization_rate >= 0.0) localization_rates.push_back(trial.localization_rate);
    if (trial.visual_frames_attempted > 0) {
      visual_frames += trial.visual_frames_attempted;
      visual_frames_fixed += trial.fixes_accepted;
      visual_seconds += trial.simulated_seconds;
    }
    for (const EstimateErrors& estimate : trial.estimates) {
      if (!pooled_position_m.count(estimate.name)) estimate_names.push_back(estimate.name);
      auto& position = pooled_position_m[estimate.name];
      auto& heading = pooled_heading_deg[estimate.name];
      auto& nees = pooled_nees[estimate.name];
      position.insert(position.end(), estimate.position_m.begin(), estimate.position_m.end());
      heading.insert(heading.end(), estimate.heading_deg.begin(), estimate.heading_deg.end());
      nees.insert(nees.end(), estimate.nees.begin(), estimate.nees.end());
    }
  }
  if (!localization_rates.empty()) metrics["localization_rate"] = ErrorStats::From(localization_rates).mean;
  if (visual_frames > 0) {
    metrics["visual_frame_success_rate"] = static_cast<double>(visual_frames_fixed) / visual_frames;
    metrics["visual_frame_rate_hz"] = visual_frames / visual_seconds;
  }
  for (const std::string& name : estimate_names) {
    // An estimate without samples (e.g. no pose fix arrived) has no error metrics, so a criterion
    // on it fails as "not measured" instead of passing with 0.
    if (pooled_position_m[name].empty()) continue;
    const ErrorStats position = ErrorStats::From(pooled_position_m[name]);
    const ErrorStats heading = ErrorStats::From(pooled_heading_deg[name]);
    metrics[name + "_position_error_mean_m"] = position.mean;
    metrics[name + "_position_error_median_m"] = position.median;
    metrics[name + "_position_error_max_m"] = position.max;
    metrics[name + "_position_error_rmse_m"] = position.rmse;
    metrics[name + "_heading_error_mean_deg"] = heading.mean;
    metrics[name + "_heading_error_median_deg"] = heading.median;
    metrics[name + "_heading_error_max_deg"] = heading.max;
    const std::vector<double>& nees = pooled_nees[name];
    if (!nees.empty()) {
      metrics[name + "_nees_mean"] = ErrorStats::From(nees).mean;
      metrics[name + "_nees_within_95_rate"] = NeesWithin95Rate(nees);
    }
  }
}

}  // namespace

nlohmann::json ComputeBatchMetrics(const std::vector<TrialResult>& trials, int trials_planned) {
  // Trials that never ran are missing from `trials` but still count in the rates' denominators.
  const int planned = std::max<int>(trials_planned, static_cast<int>(trials.size()));
  int successes = 0, completed = 0, collisions = 0, recoveries = 0, goals_reached = 0, goals_as_asked = 0;
  int goals_per_trial = 0;
  double simulated_seconds = 0.0, path_length_m = 0.0;
  std::optional<double> min_clearance_m;
  for (const TrialResult& trial : trials) {
    successes += trial.success ? 1 : 0;
    completed += trial.status == "completed" ? 1 : 0;
    collisions += trial.collisions;
    recoveries += trial.recoveries;
    if (!trial.goals.empty()) goals_per_trial = static_cast<int>(trial.goals.size());
    goals_reached += static_cast<int>(
        std::count_if(trial.goals.begin(), trial.goals.end(), [](const GoalResult& g) { return g.reached; }));
    goals_as_asked += static_cast<int>(
        std::count_if(trial.goals.begin(), trial.goals.end(), [](const GoalResult& g) { return g.reached_as_asked; }));
    simulated_seconds += trial.simulated_seconds;
    path_length_m += trial.path_length_m;
    if (trial.min_clearance_m)
      min_clearance_m = std::min(min_clearance_m.value_or(*trial.min_clearance_m), *trial.min_clearance_m);
  }

  const auto ratio = [](double numerator, double denominator) {
    return denominator > 0 ? numerator / denominator : 0.0;
  };
  const double ran = static_cast<double>(trials.size());
  nlohmann::json metrics = nlohmann::json::object();
  metrics["success_rate"] = ratio(successes, planned);
  metrics["goal_success_rate"] = ratio(goals_reached, static_cast<double>(goals_per_trial) * planned);
  // A goal the robot moved (no pose near it fitted) counts as reached where it moved it; this
  // counts only arrivals within the tolerance of the goal as asked.
  metrics["goal_success_rate_as_asked"] = ratio(goals_as_asked, static_cast<double>(goals_per_trial) * planned);
  metrics["trials_completed"] = completed;
  metrics["collisions"] = collisions;
  metrics["recoveries"] = recoveries;
  metrics["mean_trial_seconds"] = ratio(simulated_seconds, ran);
  metrics["mean_path_length_m"] = ratio(path_length_m, ran);
  if (min_clearance_m) metrics["min_clearance_m"] = *min_clearance_m;  // over all trials
  AddLocalizationMetrics(trials, metrics);
  AddBushMetrics(trials, metrics);
  AddArmMetrics(trials, metrics);
  AddTrimMetrics(trials, metrics);
  return metrics;
}

double NeesWithin95Rate(const std::vector<double>& nees) {
  if (nees.empty()) return 0.0;
  const auto within = std::count_if(nees.begin(), nees.end(), [](double v) { return v <= kChiSquare3Dof95; });
  return static_cast<double>(within) / static_cast<double>(nees.size());
}

}  // namespace trimbot::scenarios
