#pragma once
// One navigation trial in closed loop: the simulated robot in its garden, driven by the robot
// software (RobotStack, built from robot/ with the scenario's prior knowledge) through the
// scenario's goals, observed by the trial evaluator. Ground truth reaches only the evaluator (and
// the simulated pose-fix fixture when the stack is configured for it). Writes into `dir`:
// ground_truth.tum, ekf.tum, wheel_odometry.tum, pose_fixes.tum, events.csv, result.json and
// timing.json (wall-clock, kept apart so result.json is reproducible).
#include <cstdint>
#include <functional>
#include <string>

#include "evaluation/trial_result.h"
#include "loop/prepared_trial.h"
#include "loop/scenario.h"
#include "loop/setting.h"

namespace trimbot::scenarios {

struct TrialSetup {
  const Scenario* scenario = nullptr;
  const PreparedTrial* prepared = nullptr;  // the scenario's, prepared once for the batch
  ProjectPaths paths;
  std::string map_yaml;  // the robot's prior map (map_server YAML)
  std::string dir;       // this trial's output folder
  int index = 0;
  std::uint64_t seed = 0;
  bool video = false;  // write trial.mp4 (reports/trial_video.h)
  bool bag = true;     // write run.bag (reports/run_bag.h)
};

// Runs the trial; `progress(simulated_seconds)` is called about once per simulated second.
// Input errors propagate as InputError; everything the trial measured is in the result.
TrialResult RunTrial(const TrialSetup& setup, const std::function<void(double)>& progress = {});

}  // namespace trimbot::scenarios
