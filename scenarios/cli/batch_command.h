#pragma once
// `trimbot run` (a scenario's trials, headless) and `trimbot merge` (shards of a batch).
#include <CLI/CLI.hpp>

#include <string>

namespace trimbot::scenarios {

// Adds the subcommands; when one runs, its exit code goes to `exit_code` (0 all criteria pass,
// 1 a criterion failed). data_root and exit_code must outlive the app.
void AddBatchCommands(CLI::App& app, const std::string& data_root, int& exit_code);

}  // namespace trimbot::scenarios
