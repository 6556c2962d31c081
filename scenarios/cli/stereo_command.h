#pragma once
// `trimbot stereo`: one rendered ring frame through the stack's stereo (all five pairs), with the
// errors of each pair's disparity against the renderer's ground truth, disparity images and the
// merged 360-degree cloud.
#include <CLI/CLI.hpp>

#include <string>

namespace trimbot::scenarios {

// Adds the subcommand to the app; it runs when parsed. data_root must outlive the app.
void AddStereoCommand(CLI::App& app, const std::string& data_root);

}  // namespace trimbot::scenarios
