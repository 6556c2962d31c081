#include "runners/batch_executor.h"

namespace trimbot::scenarios {

std::vector<int> LocalExecutor::Run(const std::vector<BatchOptions>& batches, const BatchDone& done) {
  std::vector<int> codes;
  for (std::size_t i = 0; i < batches.size(); ++i) {
    codes.push_back(RunBatch(batches[i]));
    if (done) done(i);
  }
  return codes;
}

std::vector<int> RunBatches(BatchExecutor* executor, const std::vector<BatchOptions>& batches, const BatchDone& done) {
  if (executor != nullptr) return executor->Run(batches, done);
  LocalExecutor local;
  return local.Run(batches, done);
}

}  // namespace trimbot::scenarios
