#include "runners/ablation.h"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>

#include "loop/prior_knowledge.h"
#include "runners/batch.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kAllEffects = "all_effects";

json ReadJsonOrNull(const std::string& path) {
  std::ifstream in(path);
  if (!in) return nullptr;
  return json::parse(in, nullptr, /*allow_exceptions=*/false);
}

// The effects asked for, checked by name.
std::vector<FidelityEffect> ChosenEffects(const std::vector<std::string>& names) {
  if (names.empty()) return FidelityEffects();
  std::vector<FidelityEffect> chosen;
  for (const auto& name : names) {
    auto it = std::find_if(FidelityEffects().begin(), FidelityEffects().end(),
                           [&](const FidelityEffect& e) { return e.name == name; });
    if (it == FidelityEffects().end()) {
      std::string known;
      for (const auto& e : FidelityEffects()) known += (known.empty() ? "" : ", ") + e.name;
      throw InputError("--effect", "unknown effect '" + name + "' (known: " + known + ")");
    }
    chosen.push_back(*it);
  }
  return chosen;
}

// True when `dir` holds a finished batch of exactly this scenario file, overrides, seed and trials,
// run by this very build.
bool FinishedBatch(const BatchOptions& batch, const Scenario& scenario) {
  const json info = ReadJsonOrNull(batch.out_dir + "/batch.json");
  if (!info.is_object() || !fs::exists(batch.out_dir + "/summary.json")) return false;
  std::error_code error;
  return fs::weakly_canonical(info.value("scenario_file", ""), error) ==
             fs::weakly_canonical(batch.scenario_path, error) &&
         info.value("overrides", std::vector<std::string>{}) == batch.overrides &&
         info.value("seed", std::uint64_t{0}) == scenario.setting.seed && info.value("trials", 0) == scenario.trials &&
         info.value("shard", "") == "0/1" && info.value("build", "") == BuildFingerprint();
}

struct PlannedBatch {
  std::size_t scenario = 0;
  std::string effect;  // "" every effect on
  BatchOptions options;
  Scenario scenario_as_run;
};

std::vector<PlannedBatch> PlanBatches(const AblationOptions& options, const std::vector<FidelityEffect>& effects,
                                      std::vector<ScenarioAblation>* ablations) {
  std::vector<PlannedBatch> planned;
  std::set<std::string> names;
  std::vector<Scenario> nominals;
  for (const std::string& path : options.scenario_paths) {
    nominals.push_back(Scenario::Load(path, ParseOverrides(options.overrides)));
    const Scenario& nominal = nominals.back();
    if (!names.insert(nominal.name).second) throw InputError(path, "scenario '" + nominal.name + "' given twice");
    ablations->push_back({nominal.name, nominal.robot_reference, {}});
  }
  // Every scenario with every effect on first, then each effect off in turn: the main figures come
  // before the ablations.
  for (int e = -1; e < static_cast<int>(effects.size()); ++e) {
    for (std::size_t i = 0; i < nominals.size(); ++i) {
      const std::string& path = options.scenario_paths[i];
      const Scenario& nominal = nominals[i];
      PlannedBatch p;
      p.scenario = i;
      p.options.scenario_path = path;
      p.options.paths = options.paths;
      p.options.trials = options.trials;
      p.options.seed = options.seed;
      p.options.jobs = options.jobs;
      p.options.quiet = true;
      p.options.overrides = options.overrides;
      if (e >= 0) {
        const FidelityEffect& effect = effects[static_cast<std::size_t>(e)];
        if (effect.needs_map_recipe && !nominal.visual_map_recipe) continue;  // nothing to switch off
        p.effect = effect.name;
        p.options.overrides.insert(p.options.overrides.end(), effect.off.begin(), effect.off.end());
      }
      p.options.out_dir = options.out_dir + "/" + nominal.name + "/" + (e < 0 ? kAllEffects : "without_" + p.effect);
      // Checked before anything runs, with the batch's own seed and trial count.
      p.scenario_as_run = Scenario::Load(path, ParseOverrides(p.options.overrides));
      StackParametersFor(p.scenario_as_run, options.paths);
      if (options.seed) p.scenario_as_run.setting.seed = *options.seed;
      if (options.trials) p.scenario_as_run.trials = *options.trials;
      planned.push_back(std::move(p));
    }
  }
  return planned;
}

std::string Percent(const json& metrics, const char* key) {
  if (!metrics.contains(key)) return "-";
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << 100.0 * metrics[key].get<double>() << " %";
  return s.str();
}

std::string Centimetres(const json& metrics, const std::string& estimate) {
  const std::string mean = estimate + "_position_error_mean_m", median = estimate + "_position_error_median_m";
  if (!metrics.contains(mean)) return "-";
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << 100.0 * metrics[mean].get<double>() << " / ";
  if (metrics.contains(median))
    s << 100.0 * metrics[median].get<double>();
  else
    s << "-";
  s << " cm";
  return s.str();
}

// " (better, p 0.002)": the ablation against every effect on, when a test found a difference.
std::string Verdict(const AblationBatch& batch, const std::string& metric) {
  if (!batch.against_all) return "";
  for (const auto& m : batch.against_all->metrics) {
    if (m.metric != metric) continue;
    std::ostringstream s;
    s << std::setprecision(2);
    if (m.verdict == "regressed")
      s << " **worse** (p " << m.p_worse << ")";
    else if (m.verdict == "improved")
      s << " **better** (p " << m.p_better << ")";
    else
      s << " (=)";
    return s.str();
  }
  return "";
}

std::string FrameTime(const json& timing) {
  if (!timing.is_object() || !timing.contains("visual_localization")) return "-";
  const json& total = timing["visual_localization"]["total"];
  std::ostringstream s;
  s << std::fixed << std::setprecision(0) << total.value("median_ms", 0.0) << " (" << total.value("p90_ms", 0.0)
    << ") ms";
  return s.str();
}

std::string RealTimeFactor(const json& timing) {
  if (!timing.is_object() || !timing.contains("stages_summed_over_trials")) return "-";
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << timing["stages_summed_over_trials"].value("real_time_factor", 0.0);
  return s.str();
}

void WriteRobotRow(std::ostringstream& md, const RobotReference& robot) {
  json metrics;
  for (const auto& [name, value] : robot.metrics) metrics[name] = value;
  std::ostringstream frame;
  if (robot.frame_seconds > 0.0) frame << std::fixed << std::setprecision(0) << 1e3 * robot.frame_seconds << " ms";
  md << "| the robot | " << Percent(metrics, "success_rate") << " | " << Centimetres(metrics, "pose_fixes") << " | "
     << Centimetres(metrics, "ekf") << " | " << Percent(metrics, "localization_rate") << " | "
     << Percent(metrics, "visual_frame_success_rate") << " | " << (frame.str().empty() ? "-" : frame.str())
     << " | - |\n";
}

void WriteTwinRow(std::ostringstream& md, const AblationBatch& batch) {
  const json& metrics = batch.summary["metrics"];
  int successes = 0;
  for (const auto& trial : batch.summary["trials"]) successes += trial.value("success", false) ? 1 : 0;
  md << "| " << (batch.effect.empty() ? "twin, every effect on" : "without " + batch.effect) << " | " << successes
     << "/" << batch.summary.value("trials_planned", 0) << Verdict(batch, "success_rate") << " | "
     << Centimetres(metrics, "pose_fixes") << Verdict(batch, "pose_fix_position_error_m") << " | "
     << Centimetres(metrics, "ekf") << Verdict(batch, "ekf_position_error_m") << " | "
     << Percent(metrics, "localization_rate") << Verdict(batch, "localization_rate") << " | "
     << Percent(metrics, "visual_frame_success_rate") << " | " << FrameTime(batch.timing) << " | "
     << RealTimeFactor(batch.timing) << " |\n";
}

}  // namespace

const std::vector<FidelityEffect>& FidelityEffects() {
  static const std::vector<FidelityEffect> effects = {
      {"map_from_log",
       "the map built from the robot's own log (off: triangulated from survey poses, the truth plus survey noise)",
       {"visual_map.builder=surveyed"},
       true},
      {"wind", "foliage moving in gusty wind", {"conditions.wind.mean_speed=0"}},
      {"clouds", "clouds dimming the sun", {"conditions.clouds.cover=0"}},
      {"motion_blur", "motion blur over the exposure", {"cameras.motion_blur=false"}},
      {"calibration_error",
       "a calibration the stack does not know exactly, and a camera-IMU time offset",
       {"calibration_error.focal_relative=0", "calibration_error.principal_point_px=0",
        "calibration_error.rotation_deg=0", "calibration_error.translation_m=0",
        "calibration_error.camera_imu_time_offset_s=0"}},
  };
  return effects;
}

std::string TwinVersusRobotMarkdown(const std::vector<ScenarioAblation>& ablations) {
  std::ostringstream md;
  md << "# The twin beside the robot\n\n"
     << "Errors are means / medians over the pooled samples; rates over the trials. An ablation row has one effect "
        "off and the same trial seeds; beside each of its figures the verdict of `trimbot compare` against the row "
        "with every effect on: **better** or **worse** without the effect, or (=) when the trials show no "
        "difference. Frame time and real-time factor are wall-clock (machine-dependent).\n\n";
  for (const auto& a : ablations) {
    md << "## " << a.scenario << "\n\n"
       << "| | success | visual fix error mean / median | EKF error mean / median | localization rate | frames "
          "with a fix | localization time per frame, median (p90) | real-time factor |\n"
       << "|---|---|---|---|---|---|---|---|\n";
    if (a.robot) WriteRobotRow(md, *a.robot);
    for (const auto& batch : a.batches) WriteTwinRow(md, batch);
    md << "\n";
    if (a.robot) md << "The robot's figures: " << a.robot->source << ".\n\n";
  }
  md << "Effects:\n";
  for (const auto& e : FidelityEffects()) md << "- " << e.name << ": " << e.what << ".\n";
  return md.str();
}

json TwinVersusRobotJson(const std::vector<ScenarioAblation>& ablations) {
  json out = json::array();
  for (const auto& a : ablations) {
    json scenario{{"scenario", a.scenario}};
    if (a.robot) {
      json metrics;
      for (const auto& [name, value] : a.robot->metrics) metrics[name] = value;
      scenario["robot"] = {{"source", a.robot->source}, {"metrics", metrics}};
      if (a.robot->frame_seconds > 0.0) scenario["robot"]["frame_seconds"] = a.robot->frame_seconds;
    }
    for (const auto& batch : a.batches) {
      json row{{"effect_off", batch.effect}, {"metrics", batch.summary["metrics"]}};
      if (batch.against_all) row["comparison"] = ToJson(*batch.against_all);
      scenario["batches"].push_back(row);
    }
    out.push_back(scenario);
  }
  return out;
}

int RunAblation(const AblationOptions& options) {
  if (options.scenario_paths.empty()) throw InputError("ablate", "give at least one scenario");
  const auto effects = ChosenEffects(options.effects);
  std::vector<ScenarioAblation> ablations;
  const std::vector<PlannedBatch> planned = PlanBatches(options, effects, &ablations);
  fs::create_directories(options.out_dir);
  std::vector<BatchOptions> to_run;
  std::vector<bool> finished;
  for (const auto& p : planned) {
    finished.push_back(FinishedBatch(p.options, p.scenario_as_run));
    if (finished.back())
      std::cout << "[ablate] reusing " << p.options.out_dir << std::endl;
    else if (options.report_only)
      std::cout << "[ablate] not run yet, left out: " << p.options.out_dir << std::endl;
    else
      to_run.push_back(p.options);
  }
  std::cout << "[ablate] " << planned.size() << " batches, " << to_run.size() << " to run -> " << options.out_dir
            << std::endl;
  RunBatches(options.executor, to_run,
             [&](std::size_t i) { std::cout << "[ablate] done: " << to_run[i].out_dir << std::endl; });
  std::vector<std::string> baseline_dirs(options.scenario_paths.size());
  for (std::size_t i = 0; i < planned.size(); ++i) {
    const PlannedBatch& p = planned[i];
    if (options.report_only && !finished[i]) continue;
    if (!p.effect.empty() && baseline_dirs[p.scenario].empty()) continue;  // nothing to compare with
    const std::string summary_path = p.options.out_dir + "/summary.json";
    AblationBatch batch{p.effect, ReadJsonOrNull(summary_path), ReadJsonOrNull(p.options.out_dir + "/timing.json"), {}};
    if (!batch.summary.is_object()) throw InputError(summary_path, "missing or malformed after the batch ran");
    if (p.effect.empty()) {
      baseline_dirs[p.scenario] = p.options.out_dir;
    } else {
      const std::string baseline = baseline_dirs[p.scenario] + "/summary.json";
      batch.against_all =
          CompareBatches(ablations[p.scenario].batches.front().summary, baseline, batch.summary, summary_path);
      WriteFileAtomically(p.options.out_dir + "/comparison.json", ToJson(*batch.against_all).dump(2));
      WriteFileAtomically(p.options.out_dir + "/comparison.md", ToMarkdown(*batch.against_all));
    }
    ablations[p.scenario].batches.push_back(std::move(batch));
  }
  const std::string markdown = TwinVersusRobotMarkdown(ablations);
  WriteFileAtomically(options.out_dir + "/twin_vs_robot.md", markdown);
  WriteFileAtomically(options.out_dir + "/twin_vs_robot.json", TwinVersusRobotJson(ablations).dump(2));
  std::cout << markdown << "[ablate] outputs in " << options.out_dir << " (twin_vs_robot.md, twin_vs_robot.json)"
            << std::endl;
  return 0;
}

}  // namespace trimbot::scenarios
