// `trimbot run SCENARIO`, `trimbot suite SUITE` and `trimbot merge SHARDS` (runners/batch.h,
// runners/batch_executor.h, runners/suite.h).
#include <memory>

#include "cli/command.h"

#include "cli/cluster_options.h"
#include "runners/batch_executor.h"
#include "runners/suite.h"
#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {

void AddBatchCommands(Commands& commands) {
  CLI::App& app = commands.app();
  auto options = std::make_shared<BatchOptions>();
  auto trials = std::make_shared<int>(0);
  auto seed = std::make_shared<std::uint64_t>(0);
  auto shard = std::make_shared<std::string>("0/1");

  auto* run = app.add_subcommand("run", "run a scenario's navigation trials headless and report against its criteria");
  run->add_option("scenario", options->scenario_path, "scenario file (YAML)")->required();
  run->add_option("--out", options->out_dir, "output folder")->required();
  auto* trials_option =
      run->add_option("--trials", *trials, "number of trials (default: the scenario's)")->check(CLI::Range(1, 100000));
  auto* seed_option =
      run->add_option("--seed", *seed, "batch seed; trial i runs with seed + i (default: the scenario's)");
  run->add_option("--jobs", options->jobs, "trials in parallel (processes; default: one per hardware thread)")
      ->check(CLI::Range(1, 256));
  auto* shard_option =
      run->add_option("--shard", *shard, "run only shard i of n (trials with index % n == i), e.g. 0/4");
  run->add_flag("--keep-worlds", options->keep_worlds, "keep each trial's composed MuJoCo world");
  run->add_flag("!--no-bag", options->bag, "write no trials/NNN/run.bag (about 65 kB per simulated second)");
  run->add_flag("--video", options->video,
                "write trials/NNN/trial.mp4: a camera following the robot, cam0 and a top view (slower)");
  run->add_option("--set", options->overrides,
                  "override a scenario or stack parameter, key.path=value (repeatable), e.g. "
                  "--set stack.navigation.follower.cruise_speed=0.3 --set trials=3");
  auto cluster = AddClusterOptions(run);
  commands.OnRun(run, [options, trials, seed, shard, trials_option, seed_option, shard_option, cluster, &commands] {
    options->paths = commands.paths();
    if (trials_option->count() > 0) options->trials = *trials;
    if (seed_option->count() > 0) options->seed = *seed;
    std::tie(options->shard_index, options->shard_count) = ParseShard(*shard, "--shard");
    if (cluster->slurm && shard_option->count() > 0) throw InputError("--shard", "--slurm makes the shards itself");
    const auto executor = MakeExecutor(*cluster, options->paths, options->out_dir);
    return RunBatches(executor.get(), {*options}).front();
  });

  auto suite = std::make_shared<SuiteOptions>();
  auto suite_gardens = std::make_shared<int>(0);
  auto* suite_cmd = app.add_subcommand(
      "suite",
      "navigation over many generated gardens with seeded goals (the regression benchmark): per-garden and "
      "overall success, failure reasons, plan times");
  suite_cmd->add_option("suite", suite->suite_path, "suite file (YAML, e.g. scenarios/suites/random_gardens.yaml)")
      ->required();
  suite_cmd->add_option("--out", suite->out_dir, "output folder")->required();
  auto* gardens_option =
      suite_cmd->add_option("--gardens", *suite_gardens, "run only the first N gardens")->check(CLI::Range(1, 10000));
  suite_cmd->add_option("--jobs", suite->jobs, "trials in parallel within a garden (processes)")
      ->check(CLI::Range(1, 256));
  suite_cmd->add_option("--runner", suite->runner,
                        "run each garden with this command instead, e.g. \"/old/trimbot --data-root /old/src\" (the "
                        "same suite on another build)");
  commands.OnRun(suite_cmd, [suite, suite_gardens, gardens_option, &commands] {
    suite->paths = commands.paths();
    if (gardens_option->count() > 0) suite->gardens = *suite_gardens;
    return RunSuite(*suite);
  });

  auto shard_dirs = std::make_shared<std::vector<std::string>>();
  auto merged_out = std::make_shared<std::string>();
  auto* merge =
      app.add_subcommand("merge", "merge the output folders of a batch's shards and report on the whole batch");
  merge->add_option("shards", *shard_dirs, "output folders of `trimbot run --shard`")->required();
  merge->add_option("--out", *merged_out, "output folder of the merged batch")->required();
  commands.OnRun(
      merge, [shard_dirs, merged_out, &commands] { return MergeShards(*shard_dirs, *merged_out, commands.paths()); });
}

}  // namespace trimbot::scenarios
