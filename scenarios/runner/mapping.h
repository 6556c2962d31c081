#pragma once
// `trimbot map build`: a mapping drive - a drive plan played open loop, or a scenario whose goals
// the robot's stack drives to (on the simulated pose fixes or dead reckoning, as the map does not
// exist yet; with a seed 1000 above the scenario's) - rendered only where the map builder takes a
// keyframe, with survey poses = ground truth + seeded noise (as the real map was tied to a laser
// tracker), through the stack's MapBuilder into one map file. Writes into the output folder:
//   map.sqlite        the map (VisualMap)
//   map_stats.json    keyframes, points, observations, mean track length, reprojection RMSE, time
//                     per stage, keyframe pose errors against ground truth (survey and adjusted)
//   map_top_view.png  points over the garden, keyframe poses
#include <cstdint>
#include <optional>
#include <string>

#include "runner/world_setup.h"
#include "trimbot/visual_localization/features.h"

namespace trimbot::scenarios {

struct MapBuildOptions {
  std::string plan_path;
  std::string out_dir;
  ProjectPaths paths;
  std::optional<std::uint64_t> seed;     // the drive's (and the survey noise's) seed
  std::optional<double> seconds;         // stop the drive early
  double survey_position_sigma = 0.02;   // m per axis
  double survey_rotation_sigma_deg = 0.5;
  // Upright-SIFT or SIFT; default: the stack's (stack.yaml, with the scenario's stack section).
  std::optional<visual_localization::Descriptor> descriptor;
};

int RunMapBuild(const MapBuildOptions& options);

}  // namespace trimbot::scenarios
