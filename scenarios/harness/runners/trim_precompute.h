#pragma once
// `trimbot trim precompute`: cutting paths solved in full for targets over a grid of shapes, sizes
// and placements in front of the robot, stored in one SQLite file (stack/trimming/plan_database.h)
// that the robot adapts at run time instead of solving from scratch (reference deliverable D3.4,
// Section 1.5). The robot's arm, blade and collision model come from the robot files.
#include <string>
#include <vector>

#include "loop/setting.h"

namespace trimbot::scenarios {

struct TrimPrecomputeOptions {
  std::string out;  // the database file
  std::vector<std::string> shapes{"ball", "cylinder", "box"};
  std::vector<double> sizes{0.5, 0.7};       // m: the target's width (and height)
  std::vector<double> distances{0.85, 1.0};  // m: from base_link's origin to the target's centre
  std::vector<double> bearings_deg{0.0};     // of the target's centre from the base's x axis
  // Blade poses, rolls, tolerance and the arm's speeds: the stack's (robot/config/stack.yaml trim, arm).
};

// Exit code: kExitSuccess, kExitBadInput (an unknown shape, a size or distance out of range).
int RunTrimPrecompute(const TrimPrecomputeOptions& options, const ProjectPaths& paths);

}  // namespace trimbot::scenarios
