#pragma once
// `trimbot sweep` and `trimbot tune`: parameter sweeps and derivative-free tuning of a scenario
// (runner/sweep.h, runner/tune.h).
#include <CLI/CLI.hpp>

#include <string>

namespace trimbot::scenarios {

void AddTuningCommands(CLI::App& app, const std::string& data_root, int& exit_code);

}  // namespace trimbot::scenarios
