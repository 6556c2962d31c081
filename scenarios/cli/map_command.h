#pragma once
// `trimbot map build`: a visual localization map from a mapping drive (runner/mapping.h).
#include <CLI/CLI.hpp>

#include <string>

namespace trimbot::scenarios {

void AddMapCommands(CLI::App& app, const std::string& data_root, int& exit_code);

}  // namespace trimbot::scenarios
