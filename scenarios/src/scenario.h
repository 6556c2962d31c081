#pragma once
// A navigation scenario: the garden, the robot's start and goals, conditions, noise, faults, the
// stand-in visual localization, how many trials with which seed, and the pass criteria. Read
// strictly from YAML (unknown keys and wrong types are errors with file, line and key).
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "trimbot/garden/conditions.h"
#include "trimbot/sim/faults.h"
#include "trimbot/sim/pose_fix_model.h"
#include "trimbot/sim/world_builder.h"

namespace trimbot::scenarios {

struct PassCriterion {
  std::string metric;       // a batch metric (see ComputeBatchMetrics)
  std::string comparison;   // ">=" (min) or "<=" (max)
  double threshold = 0.0;
};

struct Scenario {
  std::string source;       // file it was read from
  std::string name;
  std::string description;
  std::string garden;       // name or file
  double map_resolution = 0.05;        // m: the robot's prior map, made from the garden's object map
  double map_clearance_height = 1.0;   // m: objects whose lowest point is higher are not obstacles
  sim::Pose2D start;
  std::vector<Eigen::Vector2d> goals;  // map frame, in order
  double speed = 0.25;                 // m/s cruise speed
  double goal_tolerance = 0.3;         // m: a goal counts as reached within this (ground truth)
  garden::Conditions conditions;
  std::uint64_t seed = 1;              // trial i runs with seed + i
  int trials = 1;
  double time_limit = 300.0;           // s of simulated time per trial
  double wall_time_limit = 1800.0;     // s of wall-clock time per trial before it is killed
  bool render_cameras = false;         // the EKF does not need images; rendering costs ~1 s per ring frame
  double resolution_scale = 0.5;       // when rendering
  double imu_noise_scale = 1.0;
  double wheel_slip_scale = 1.0;
  sim::PoseFixModelParameters pose_fixes;
  std::vector<sim::Fault> faults;
  std::vector<PassCriterion> criteria;

  static Scenario Load(const std::string& path);
};

// Names a criterion may use.
bool IsKnownMetric(const std::string& name);

}  // namespace trimbot::scenarios
