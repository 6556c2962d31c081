// `trimbot sweep`, `trimbot tune` and `trimbot ablate`: parameter sweeps, derivative-free tuning
// and the fidelity effects switched off in turn (runners/sweep.h, runners/tune.h, runners/ablation.h).
#include <cstdint>
#include <memory>
#include <string>

#include "cli/command.h"

#include "cli/cluster_options.h"
#include "runners/ablation.h"
#include "runners/sweep.h"
#include "runners/tune.h"

namespace trimbot::scenarios {
namespace {

// What sweep and tune share: each point or evaluation is a batch of `--trials` trials from
// `--seed`, `--jobs` at once, with `--set` overrides, here or on a cluster. Adds those options to
// `command` and runs `run(*options)` with them.
template <class Options>
void AddBatchOptionsAndRun(Commands& commands, CLI::App* command, std::shared_ptr<Options> options,
                           const std::string& per, int (*run)(const Options&)) {
  auto trials = std::make_shared<int>(0);
  auto seed = std::make_shared<std::uint64_t>(0);
  auto* trials_option = command->add_option("--trials", *trials, "trials per " + per + " (default: the scenario's)")
                            ->check(CLI::Range(1, 100000));
  auto* seed_option = command->add_option("--seed", *seed, "batch seed of every " + per + " (default: the scenario's)");
  command->add_option("--jobs", options->jobs, "trials in parallel (processes; default: one per hardware thread)")
      ->check(CLI::Range(1, 256));
  command->add_option("--set", options->overrides, "override for every " + per + ", key.path=value (repeatable)");
  auto cluster = AddClusterOptions(command);
  commands.OnRun(command, [options, trials, seed, trials_option, seed_option, cluster, run, &commands] {
    options->paths = commands.paths();
    if (trials_option->count() > 0) options->trials = *trials;
    if (seed_option->count() > 0) options->seed = *seed;
    const auto executor = MakeExecutor(*cluster, options->paths, options->out_dir);
    options->executor = executor.get();
    return run(*options);
  });
}

void AddSweep(Commands& commands) {
  auto options = std::make_shared<SweepOptions>();
  auto* sweep =
      commands.app().add_subcommand("sweep", "run a scenario over the product of parameter grids, with 95 % intervals");
  sweep->add_option("scenario", options->scenario_path, "scenario file (YAML)")->required();
  sweep->add_option("--grid", options->grids, "key.path=v1,v2,... (repeatable; the product is swept)")->required();
  sweep->add_option("--out", options->out_dir, "output folder")->required();
  AddBatchOptionsAndRun(commands, sweep, options, "point", &RunSweep);
}

void AddTune(Commands& commands) {
  auto options = std::make_shared<TuneOptions>();
  auto* tune =
      commands.app().add_subcommand("tune", "tune parameters of a scenario with a derivative-free optimizer (NLopt)");
  tune->add_option("scenario", options->scenario_path, "scenario file (YAML)")->required();
  tune->add_option("--space", options->space_path,
                   "parameter space (YAML: parameters with key, min, max, log, integer)")
      ->required();
  tune->add_option("--objective", options->objective, "batch metric to optimize, e.g. ekf_position_error_mean_m")
      ->required();
  tune->add_flag("--maximize", options->maximize, "maximize the objective (default: minimize)");
  tune->add_option("--method", options->method, "bobyqa (local) or direct (global DIRECT-L)");
  tune->add_option("--budget", options->budget_trials, "trials the search may use")->check(CLI::Range(1, 1000000));
  tune->add_option("--out", options->out_dir, "output folder")->required();
  AddBatchOptionsAndRun(commands, tune, options, "evaluation", &RunTune);
}

void AddAblate(Commands& commands) {
  auto options = std::make_shared<AblationOptions>();
  auto* ablate = commands.app().add_subcommand(
      "ablate",
      "the twin beside the real robot: each scenario with every fidelity effect on, then each effect off in turn on "
      "the same seeds, compared (twin_vs_robot.md)");
  ablate->add_option("scenarios", options->scenario_paths, "scenario files (YAML)")->required();
  std::string effects;
  for (const auto& e : FidelityEffects()) effects += (effects.empty() ? "" : ", ") + e.name;
  ablate->add_option("--effect", options->effects,
                     "an effect to switch off (repeatable; default all: " + effects + ")");
  ablate->add_option("--out", options->out_dir, "output folder (finished batches in it are reused)")->required();
  ablate->add_flag("--report-only", options->report_only, "run nothing: the table of the batches finished so far");
  AddBatchOptionsAndRun(commands, ablate, options, "batch", &RunAblation);
}

}  // namespace

void AddTuningCommands(Commands& commands) {
  AddSweep(commands);
  AddTune(commands);
  AddAblate(commands);
}

}  // namespace trimbot::scenarios
