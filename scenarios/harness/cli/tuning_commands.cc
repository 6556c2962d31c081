// `trimbot sweep` and `trimbot tune`: parameter sweeps and derivative-free tuning of a scenario
// (runners/sweep.h, runners/tune.h).
#include <memory>

#include "cli/command.h"

#include "cli/cluster_options.h"
#include "runners/sweep.h"
#include "runners/tune.h"

namespace trimbot::scenarios {
namespace {

void AddSweep(Commands& commands) {
  CLI::App& app = commands.app();
  auto options = std::make_shared<SweepOptions>();
  auto trials = std::make_shared<int>(0);
  auto seed = std::make_shared<std::uint64_t>(0);
  auto* sweep = app.add_subcommand("sweep", "run a scenario over the product of parameter grids, with 95 % intervals");
  sweep->add_option("scenario", options->scenario_path, "scenario file (YAML)")->required();
  sweep->add_option("--grid", options->grids, "key.path=v1,v2,... (repeatable; the product is swept)")->required();
  sweep->add_option("--out", options->out_dir, "output folder")->required();
  auto* trials_option = sweep->add_option("--trials", *trials, "trials per point (default: the scenario's)")
                            ->check(CLI::Range(1, 100000));
  auto* seed_option = sweep->add_option("--seed", *seed, "batch seed of every point (default: the scenario's)");
  sweep->add_option("--jobs", options->jobs, "trials in parallel (processes; default: one per hardware thread)")
      ->check(CLI::Range(1, 256));
  sweep->add_option("--set", options->overrides, "override for every point, key.path=value (repeatable)");
  auto cluster = AddClusterOptions(sweep);
  commands.OnRun(sweep, [options, trials, seed, trials_option, seed_option, cluster, &commands] {
    options->paths = commands.paths();
    if (trials_option->count() > 0) options->trials = *trials;
    if (seed_option->count() > 0) options->seed = *seed;
    const auto executor = MakeExecutor(*cluster, options->paths, options->out_dir);
    options->executor = executor.get();
    return RunSweep(*options);
  });
}

void AddTune(Commands& commands) {
  CLI::App& app = commands.app();
  auto options = std::make_shared<TuneOptions>();
  auto trials = std::make_shared<int>(0);
  auto seed = std::make_shared<std::uint64_t>(0);
  auto* tune = app.add_subcommand("tune", "tune parameters of a scenario with a derivative-free optimizer (NLopt)");
  tune->add_option("scenario", options->scenario_path, "scenario file (YAML)")->required();
  tune->add_option("--space", options->space_path,
                   "parameter space (YAML: parameters with key, min, max, log, integer)")
      ->required();
  tune->add_option("--objective", options->objective, "batch metric to optimize, e.g. ekf_position_error_mean_m")
      ->required();
  tune->add_flag("--maximize", options->maximize, "maximize the objective (default: minimize)");
  tune->add_option("--method", options->method, "bobyqa (local) or direct (global DIRECT-L)");
  tune->add_option("--budget", options->budget_trials, "trials the search may use")->check(CLI::Range(1, 1000000));
  auto* trials_option = tune->add_option("--trials", *trials, "trials per evaluation (default: the scenario's)")
                            ->check(CLI::Range(1, 100000));
  auto* seed_option = tune->add_option("--seed", *seed, "seed of the tuning trials (the same at every point)");
  tune->add_option("--jobs", options->jobs, "trials in parallel (processes; default: one per hardware thread)")
      ->check(CLI::Range(1, 256));
  tune->add_option("--out", options->out_dir, "output folder")->required();
  tune->add_option("--set", options->overrides, "override for every evaluation, key.path=value (repeatable)");
  auto cluster = AddClusterOptions(tune);
  commands.OnRun(tune, [options, trials, seed, trials_option, seed_option, cluster, &commands] {
    options->paths = commands.paths();
    if (trials_option->count() > 0) options->trials = *trials;
    if (seed_option->count() > 0) options->seed = *seed;
    const auto executor = MakeExecutor(*cluster, options->paths, options->out_dir);
    options->executor = executor.get();
    return RunTune(*options);
  });
}

}  // namespace

void AddTuningCommands(Commands& commands) {
  AddSweep(commands);
  AddTune(commands);
}

}  // namespace trimbot::scenarios
