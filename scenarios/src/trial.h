#pragma once
// One navigation trial in closed loop: the simulated robot in its garden, and the robot's stack
// (EKF of wheel odometry, IMU and pose fixes; planner; path follower) driving it through the
// scenario's goals. Ground truth is read only here, for the evaluation. Writes into `dir`:
// ground_truth.tum, ekf.tum, wheel_odometry.tum, pose_fixes.tum (TUM, usable with evo),
// events.csv (navigation events) and result.json.
#include <cstdint>
#include <functional>
#include <string>

#include "project_paths.h"
#include "scenario.h"
#include "trial_result.h"

namespace trimbot::scenarios {

struct TrialSetup {
  const Scenario* scenario = nullptr;
  ProjectPaths paths;
  std::string map_yaml;   // the robot's prior map (map_server YAML)
  std::string dir;        // this trial's output folder
  int index = 0;
  std::uint64_t seed = 0;
};

// Runs the trial; `progress(simulated_seconds)` is called about once per simulated second.
// Input errors propagate as InputError; everything the trial measured is in the result.
TrialResult RunTrial(const TrialSetup& setup, const std::function<void(double)>& progress = {});

}  // namespace trimbot::scenarios
