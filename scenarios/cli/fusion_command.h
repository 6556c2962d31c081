#pragma once
// `trimbot fusion`: local fusion in the twin. Drives a plan, makes a 360-degree stereo cloud from
// the ring every few frames, registers each cloud to the previous one with DUGMA starting from the
// wheel-odometry guess, and reports how much registration reduces the error of the relative pose
// (reference deliverable D3.4, Figures 25/26: translation 11.4 -> 5.8 cm, rotation 1.08 -> 1.46 deg).
#include <CLI/CLI.hpp>

#include <string>

namespace trimbot::scenarios {

void AddFusionCommand(CLI::App& app, const std::string& data_root, int& exit_code);

}  // namespace trimbot::scenarios
