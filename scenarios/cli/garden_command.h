#pragma once
// `trimbot garden ...`: import, generate and export gardens.
#include <CLI/CLI.hpp>

#include "runner/world_setup.h"

namespace trimbot::scenarios {

// Adds the garden subcommands to the app; they run when parsed. data_root must outlive the app.
void AddGardenCommands(CLI::App& app, const std::string& data_root);

}  // namespace trimbot::scenarios
