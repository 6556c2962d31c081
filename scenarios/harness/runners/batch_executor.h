#pragma once
// Where batches run: here, as child processes of this one (RunBatch), or spread over a cluster
// (runners/slurm_executor.h). `run`, `sweep` and `tune` hand their batches to an executor, so the
// same command scales out without a second code path for the trials. Whatever runs them, each
// batch's output folder ends up the same: summary.json is byte-identical for the same scenario,
// overrides and seeds.
#include <functional>
#include <memory>
#include <vector>

#include "runners/batch.h"

namespace trimbot::scenarios {

using BatchDone = std::function<void(std::size_t batch)>;

class BatchExecutor {
 public:
  virtual ~BatchExecutor() = default;
  // Runs every batch into its out_dir; returns each batch's exit code (0: its criteria hold, 1: one
  // failed). `done(i)` is called as batch i's output is complete. Bad input throws InputError before
  // any batch starts.
  virtual std::vector<int> Run(const std::vector<BatchOptions>& batches, const BatchDone& done = {}) = 0;
};

// The batches one after the other on this machine, each with its own `jobs` trial processes.
class LocalExecutor : public BatchExecutor {
 public:
  std::vector<int> Run(const std::vector<BatchOptions>& batches, const BatchDone& done = {}) override;
};

// `executor`, or a LocalExecutor when it is null.
std::vector<int> RunBatches(BatchExecutor* executor, const std::vector<BatchOptions>& batches,
                            const BatchDone& done = {});

}  // namespace trimbot::scenarios
