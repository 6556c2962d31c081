#pragma once
// `trimbot fusion`: local fusion in the twin. Drives a plan, makes a 360-degree stereo cloud from
// the ring every few frames, registers each cloud to the previous one with DUGMA starting from the
// wheel-odometry guess, and reports how much registration reduces the error of the relative pose
// (reference deliverable D3.4, Figures 25/26: translation 11.4 -> 5.8 cm, rotation 1.08 -> 1.46 deg).
#include <string>

#include "loop/setting.h"
#include "trimbot/stack/stack_parameters.h"  // perception::LocalFusionOptions

namespace trimbot::scenarios {

struct FusionDriveOptions {
  std::string plan;  // drive plan (YAML)
  std::string out;   // fusion.json and the world go here
  perception::LocalFusionOptions fusion{true, 1.0, 4, 0.02};
  int clouds = 20;  // registrations
};

// Prints each registration's errors and writes fusion.json; returns the exit code.
int RunFusionDrive(const FusionDriveOptions& options, const ProjectPaths& paths);

}  // namespace trimbot::scenarios
