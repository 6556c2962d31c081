#pragma once
// A parameter sweep: the product of grids (`key=v1,v2,...`), each point a batch of the scenario
// with those overrides and the same trial seeds (common random numbers: differences between
// points are the parameters', not the seeds'). Writes into the output folder:
//   points/NNN/            each point's batch (summary.json, plots, trials)
//   sweep.csv, sweep.json  per point its values and each metric with a 95 % interval
//   plots/M_vs_K.png       metric M against parameter K, one line per combination of the others
// Every point's scenario is read and checked before anything runs.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loop/setting.h"
#include "runners/batch_executor.h"

namespace trimbot::scenarios {

struct SweepGrid {
  std::string key;
  std::vector<std::string> values;  // YAML scalars as given
};
// "key=v1,v2,..." -> grid; throws InputError naming --grid on an empty key or value list.
SweepGrid ParseGrid(const std::string& text);

struct SweepOptions {
  std::string scenario_path;
  std::string out_dir;
  ProjectPaths paths;
  std::vector<std::string> grids;      // key=v1,v2,...
  std::vector<std::string> overrides;  // --set for every point
  std::optional<int> trials;
  std::optional<std::uint64_t> seed;
  int jobs = DefaultJobs();
  BatchExecutor* executor = nullptr;  // where the points run (null: here); all points at once
};

// Runs the sweep; returns 0 (a sweep reports, it does not judge). Bad input throws InputError.
int RunSweep(const SweepOptions& options);

}  // namespace trimbot::scenarios
