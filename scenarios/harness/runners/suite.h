#pragma once
// `trimbot suite SUITE`: navigation over many generated gardens, the benchmark for navigation
// regressions. A suite file (scenarios/suites/) names how many gardens, the generator's ranges
// (each garden draws its own parameters from them, seeded by the garden's seed), how many goals
// per garden and the scenario every garden runs under (stack, localization, time limit, trials).
// For each garden the suite generates the garden file, places the start and the goals by a seeded
// rule that never asks the planner (uniform over the cells where base_link keeps the outline's
// half-width plus a margin from every obstacle; the start where the base can turn round), writes a
// scenario file and runs it as a batch.
//
// Output folder:
//   gardens/NNN/garden.yaml, scenario.yaml   what each garden ran (replay: trimbot run scenario.yaml)
//   gardens/NNN/batch/                      its batch (summary.json, trajectories.png, trials/)
//   summary.json, junit.xml                 every garden's trials as one batch of the suite's name,
//                                           against the suite's criteria (`trimbot compare` reads it)
//   suite.json, suite.md                    per garden: seed, drawn parameters, goals reached,
//                                           contacts, why goals were given up; failure reasons
//                                           counted; the plans' wall times (median, p90)
#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loop/setting.h"
#include "trimbot/common/pose2.h"
#include "trimbot/garden/garden.h"

namespace trimbot::scenarios {

struct SuiteOptions {
  std::string suite_path;
  std::string out_dir;
  ProjectPaths paths;
  std::optional<int> gardens;  // run only the first this many gardens (a CI slice)
  int jobs = 1;                // trials in parallel within a garden's batch
  // Run each garden's batch with this command instead of this executable ("BIN [--data-root DIR]";
  // the suite appends `run SCENARIO --out DIR --jobs N`): the same suite on another build.
  std::string runner;
};

// The start and goals of one garden.
struct SuiteLayout {
  Pose2 start;
  std::vector<Eigen::Vector2d> goals;
};

// Start and `goals` goals drawn uniformly (seeded) from the cells of `garden`'s occupancy map
// (resolution 0.05 m, objects' parts below `clearance_height`) whose distance to the nearest obstacle is at least
// `min_distance`, in the largest connected region of them (inside the fence); the start's heading
// uniform. Throws InputError naming `what` when no cell
// qualifies.
// The start is drawn the same way from the cells at least `start_distance` from every obstacle (the
// outline's reach plus the margin: the base fits there at any heading).
SuiteLayout PlaceSuiteLayout(const garden::Garden& garden, double clearance_height, double min_distance,
                             double start_distance, int goals, std::uint64_t seed, const std::string& what);

// Runs the suite and writes its reports; returns the exit code (1 when a suite criterion fails).
// Bad input throws InputError naming the file and key.
int RunSuite(const SuiteOptions& options);

}  // namespace trimbot::scenarios
