#pragma once
// `trimbot ablate`: the twin beside the real robot, and what each of the twin's fidelity effects
// does to the figures. Per scenario: one batch as the scenario is written (every effect on), then
// one batch per effect with that effect off, all on the same trial seeds (common random numbers:
// differences are the effect's, not the seeds'); each ablation is compared with the full batch
// (evaluation/comparison.h), and the robot's own figures (the scenario's robot_reference) stand
// beside them. Writes into the output folder:
//   <scenario>/all_effects/, <scenario>/without_<effect>/   each batch (summary.json, timing.json, plots)
//   <scenario>/without_<effect>/comparison.{json,md}       per metric the verdict against all_effects
//   twin_vs_robot.md, twin_vs_robot.json                   the table
// A batch folder whose batch.json records the same scenario file, overrides, seed and trials and that
// holds a summary.json is reused, so an interrupted ablation resumes where it stopped (and
// `report_only` writes the table of what has finished so far).
#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "evaluation/comparison.h"
#include "loop/scenario.h"
#include "runners/batch_executor.h"

namespace trimbot::scenarios {

// A way the twin is made as hard as the garden, and the overrides that switch it off.
struct FidelityEffect {
  std::string name;               // without_<name>
  std::string what;               // the effect, in a phrase
  std::vector<std::string> off;   // --set key=value turning it off
  bool needs_map_recipe = false;  // only where the scenario builds its map from a mapping drive
};
// Every effect the twin has, in report order.
const std::vector<FidelityEffect>& FidelityEffects();

struct AblationOptions {
  std::vector<std::string> scenario_paths;
  std::string out_dir;
  ProjectPaths paths;
  std::vector<std::string> effects;    // names to switch off in turn (empty: every effect)
  std::vector<std::string> overrides;  // --set for every batch
  std::optional<int> trials;
  std::optional<std::uint64_t> seed;
  int jobs = DefaultJobs();
  BatchExecutor* executor = nullptr;  // where the batches run (null: here)
  bool report_only = false;           // run nothing: the report of the batches finished so far
};

// Runs the batches and writes the reports; returns 0 (an ablation reports, it does not judge).
// Bad input (a scenario, an unknown effect) throws InputError before anything runs.
int RunAblation(const AblationOptions& options);

// One finished batch of an ablation, as the report reads it.
struct AblationBatch {
  std::string effect;                     // "" for the batch with every effect on
  nlohmann::json summary;                 // its summary.json
  nlohmann::json timing;                  // its timing.json (wall-clock; may be null)
  std::optional<Comparison> against_all;  // the ablations': against the batch with every effect on
};
struct ScenarioAblation {
  std::string scenario;
  std::optional<RobotReference> robot;
  std::vector<AblationBatch> batches;  // every effect on first
};

// The twin-versus-robot table (Markdown) and its JSON form.
std::string TwinVersusRobotMarkdown(const std::vector<ScenarioAblation>& ablations);
nlohmann::json TwinVersusRobotJson(const std::vector<ScenarioAblation>& ablations);

}  // namespace trimbot::scenarios
