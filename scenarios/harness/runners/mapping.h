#pragma once
// `trimbot map build`: a mapping drive - a drive plan played open loop, or a scenario whose goals
// the robot's stack drives to (on the simulated pose fixes or dead reckoning, as the map does not
// exist yet; with a seed 1000 above the scenario's, from its believed start) - rendered only where
// the map builder takes a keyframe, through the stack's MapBuilder into one map file. The log
// builder (default) gets the robot's IMU and wheel ticks (its odometry places the keyframes) and
// the garden as surveyed (with the survey's errors, for the tie); the surveyed builder gets survey
// poses = ground truth + seeded noise. The truth at each keyframe goes to the evaluation only.
// Writes into the output folder:
//   map.sqlite        the map (VisualMap)
//   map_stats.json    keyframes, points, observations, mean track length, reprojection RMSE, time
//                     per stage; log: stereo, loops, wheel scales, the tie, and the evaluation
//                     (keyframe ATE unaligned and SE(3)-aligned, RPE, the odometry's, map points
//                     against the true surfaces); surveyed: keyframe errors (survey and adjusted)
//   map_top_view.png  points over the garden, keyframe poses
//   keyframes.tum, keyframes_odometry.tum, keyframes_truth.tum, loops.csv   (log)
#include <cstdint>
#include <optional>
#include <string>

#include "loop/map_recipe.h"
#include "loop/setting.h"
#include "trimbot/visual_localization/features.h"
#include "trimbot/visual_localization/map_builder.h"

namespace trimbot::scenarios {

struct MapBuildOptions {
  MapRecipe recipe;
  std::string out_dir;
  ProjectPaths paths;
};

int RunMapBuild(const MapBuildOptions& options);

// The map builder's settings for a recipe whose descriptor is `descriptor`: what RunMapBuild uses,
// and what a cached map's key records.
visual_localization::MapBuilderOptions MapBuilderOptionsFor(const MapRecipe& recipe,
                                                            visual_localization::Descriptor descriptor);

}  // namespace trimbot::scenarios
