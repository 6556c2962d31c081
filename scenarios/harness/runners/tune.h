#pragma once
// Tuning without hardware: a derivative-free optimizer (NLopt's BOBYQA, or its global DIRECT-L)
// over a declared parameter space, each evaluation a batch of the scenario with the same trial
// seeds (common random numbers), within a budget of trials. The best point is then re-run on fresh
// seeds beside the scenario as it is, and both figures are reported: the tuned-seed objective
// flatters (it was selected on those seeds), the fresh-seed one is the honest estimate.
//
// Space file (YAML):
//   parameters:
//     - {key: stack.navigation.follower.lookahead, min: 0.3, max: 1.2}
//     - {key: stack.ekf.fix_gate_chi2, min: 4, max: 40, log: true}
//     - {key: stack.navigation.planner.iterations, min: 1000, max: 6000, integer: true}
// Outputs: evaluations/NNN/ (each batch), fresh/best, fresh/default, tune.json, convergence.png.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loop/setting.h"
#include "runners/batch_executor.h"

namespace trimbot::scenarios {

struct TuneParameter {
  std::string key;
  double min = 0.0, max = 1.0;
  bool log = false;      // search log(value) uniformly
  bool integer = false;  // round to whole numbers
};

struct TuneSpace {
  std::vector<TuneParameter> parameters;
  // Throws InputError naming the file, line and key.
  static TuneSpace Load(const std::string& path);
};

struct TuneOptions {
  std::string scenario_path;
  std::string space_path;
  std::string objective;  // a batch metric (summary.json "metrics")
  bool maximize = false;
  std::string method = "bobyqa";      // bobyqa (local) | direct (global, DIRECT-L)
  int budget_trials = 60;             // trials for the search (fresh-seed runs not counted)
  std::optional<int> trials;          // per evaluation (default: the scenario's)
  std::optional<std::uint64_t> seed;  // tuning seeds; fresh seeds start 1,000,000 higher
  int jobs = DefaultJobs();
  std::string out_dir;
  ProjectPaths paths;
  std::vector<std::string> overrides;  // --set for every evaluation
  BatchExecutor* executor = nullptr;   // where each evaluation's batch runs (null: here)
};

// Runs the search; returns 0 when the best point beats the scenario as it is on fresh seeds, 1
// when it does not (reported as such). Bad input throws InputError.
int RunTune(const TuneOptions& options);

}  // namespace trimbot::scenarios
