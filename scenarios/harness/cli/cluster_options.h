#pragma once
// The options by which `run`, `sweep` and `tune` hand their batches to a Slurm cluster instead of
// running them here (runners/slurm_executor.h).
#include <CLI/CLI.hpp>

#include <memory>
#include <string>
#include <vector>

#include "runners/batch_executor.h"
#include "runners/slurm_executor.h"

namespace trimbot::scenarios {

struct ClusterOptions {
  bool slurm = false;
  SlurmOptions options;
};

// Adds --slurm, --partition, --max-jobs, --trials-per-task, --cpus-per-task, --retries,
// --work-dir, --poll-seconds to `command`.
std::shared_ptr<ClusterOptions> AddClusterOptions(CLI::App* command);

// A SlurmExecutor when --slurm was given (checked before anything is submitted; the work folder
// defaults to `out_dir` + ".slurm"), else null: the batches run here.
std::unique_ptr<BatchExecutor> MakeExecutor(const ClusterOptions& cluster, const ProjectPaths& paths,
                                            const std::string& out_dir);

}  // namespace trimbot::scenarios
