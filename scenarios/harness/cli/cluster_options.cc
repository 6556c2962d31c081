#include "cli/cluster_options.h"

#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {

std::shared_ptr<ClusterOptions> AddClusterOptions(CLI::App* command) {
  auto cluster = std::make_shared<ClusterOptions>();
  SlurmOptions& o = cluster->options;
  const std::string group = "Slurm (run the batches as a job array; see docs/cluster.md)";
  CLI::Option* slurm =
      command->add_flag("--slurm", cluster->slurm, "submit the trials to Slurm as a job array, wait, and merge")
          ->group(group);
  command->add_option("--partition", o.partition, "Slurm partition (default: the cluster's)")->group(group);
  command->add_option("--max-jobs", o.max_jobs, "array tasks running at once (0: no limit)")
      ->check(CLI::Range(0, 100000))
      ->group(group);
  command->add_option("--trials-per-task", o.trials_per_task, "trials each array task runs")
      ->check(CLI::Range(1, 100000))
      ->group(group);
  command->add_option("--cpus-per-task", o.cpus_per_task, "CPUs per array task (its trials in parallel)")
      ->check(CLI::Range(1, 256))
      ->group(group);
  command->add_option("--retries", o.retries, "resubmissions of a failed task")->check(CLI::Range(0, 10))->group(group);
  command->add_option("--work-dir", o.work_dir, "shared folder for the tasks' outputs and logs (default: OUT.slurm)")
      ->group(group);
  command->add_option("--poll-seconds", o.poll_seconds, "how often the job's state is read")
      ->check(CLI::Range(0.1, 3600.0))
      ->group(group);
  for (CLI::Option* option : command->get_options()) {
    if (option->get_group() == group && option != slurm) option->needs(slurm);
  }
  return cluster;
}

std::unique_ptr<BatchExecutor> MakeExecutor(const ClusterOptions& cluster, const ProjectPaths& paths,
                                            const std::string& out_dir) {
  if (!cluster.slurm) return nullptr;
  SlurmOptions options = cluster.options;
  if (options.work_dir.empty()) options.work_dir = out_dir + ".slurm";
  return std::make_unique<SlurmExecutor>(options, paths, std::vector<std::string>{out_dir});
}

}  // namespace trimbot::scenarios
