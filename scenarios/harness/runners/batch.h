#pragma once
// A batch of trials of one scenario: each trial runs in its own child process (a crash or a hang
// is recorded as a failed trial with its seed, and the batch goes on), up to `jobs` at a time; a
// shard i/n runs the trials whose index is i modulo n, so a batch can be spread over machines and
// the shards merged afterwards. Trial i runs with seed (batch seed + i), so any trial is replayed
// with `--seed <its seed> --trials 1`.
//
// Output folder:
//   batch.json                    scenario file, seed, trials, shard of this run
//   scenario.yaml                 copy of the scenario file
//   map/map.{png,yaml}            the robot's prior map (map_server)
//   trials/NNN/                   per trial: result.json, *.tum, events.csv; map/ its own prior
//                                 map when the survey is drawn per trial (then map/ above is the
//                                 survey of the batch's seed, shown under the batch's plots)
//   summary.json, junit.xml       batch metrics and pass criteria (expected / actual / pass);
//                                 summary.json is the same, byte for byte, for the same scenario and seed
//   timing.json                   wall-clock seconds per trial
//   trajectories.png, localization_errors.png
#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "loop/prepared_trial.h"
#include "loop/scenario.h"
#include "loop/setting.h"

namespace trimbot::scenarios {

// Trials run in their own processes, by default one per hardware thread.
inline int DefaultJobs() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

struct BatchOptions {
  std::string scenario_path;
  std::string out_dir;
  ProjectPaths paths;
  std::optional<int> trials;          // overrides the scenario's
  std::optional<std::uint64_t> seed;  // overrides the scenario's
  int jobs = DefaultJobs();
  int shard_index = 0, shard_count = 1;
  bool keep_worlds = false;            // keep each trial's composed MuJoCo prepared (large textures)
  std::vector<std::string> overrides;  // --set key.path=value, applied to the scenario file
  bool quiet = false;                  // no per-trial lines or report listing (sweeps, tuning)
  bool video = false;                  // each trial writes trial.mp4
  bool bag = true;                     // each trial writes run.bag
};

// A trial's folder in a batch's output folder: <out>/trials/NNN.
std::string TrialDir(const std::string& out, int index);

// Runs the batch (or this shard of it) and writes the reports. Returns the exit code: 0 when every
// pass criterion holds, 1 when one fails. Bad input throws InputError.
int RunBatch(const BatchOptions& options);

// A fingerprint of the running trimbot executable (FNV-1a of its bytes, as hex): every batch.json
// records it, and `trimbot ablate` reuses only batches of the same build.
std::string BuildFingerprint();

// Merges the output folders of shards of one batch into `out_dir` and writes the reports of the
// whole batch. Returns the exit code as RunBatch.
int MergeShards(const std::vector<std::string>& shard_dirs, const std::string& out_dir,
                const ProjectPaths& paths = ProjectPaths::Default(), bool quiet = false);

// What a batch is run from: its scenario with its overrides and its prepared trial, read and checked
// before anything is written. Throws InputError naming the file and key.
struct BatchInputs {
  Scenario scenario;
  PreparedTrial prepared;
};
BatchInputs LoadBatchInputs(const BatchOptions& options);

// "i/n" -> (i, n), 0 <= i < n; throws InputError naming `what` on bad text.
std::pair<int, int> ParseShard(const std::string& text, const std::string& what);

}  // namespace trimbot::scenarios
