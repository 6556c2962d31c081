#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "trimbot/visual_localization/features.h"
#include "trimbot/visual_localization/map_builder.h"

namespace trimbot::scenarios {

// What a map is made from: the mapping drive and the survey. A scenario may name one instead of a
// map file (`visual_map: {mapping_drive: PLAN}`); the map is then built on first use and cached
// (runners/map_cache.h).
struct MapRecipe {
  std::string plan_path;              // the mapping drive: a drive plan, or a scenario with goals
  std::optional<std::uint64_t> seed;  // the drive's (and the survey noise's) seed; default: the plan's
  std::optional<double> seconds;      // stop the drive early
  // From the robot's own log (odometry, loop closure, tie to the surveyed outlines), or from
  // survey poses (truth plus the sigmas below: a laser tracker the user would need).
  visual_localization::KeyframePoses builder = visual_localization::KeyframePoses::kOdometry;
  double survey_position_sigma = 0.02;  // m per axis (surveyed builder)
  double survey_rotation_sigma_deg = 0.5;
  // Upright-SIFT or SIFT; default: the stack's (stack.yaml, with the scenario's stack section).
  std::optional<visual_localization::Descriptor> descriptor;
};

}  // namespace trimbot::scenarios
