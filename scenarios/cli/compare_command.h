#pragma once
// `trimbot compare BASELINE CANDIDATE`: is the candidate batch worse than the baseline beyond
// trial-to-trial noise? (see eval/comparison.h). Exit code 1 on a regression.
#include <CLI/CLI.hpp>

namespace trimbot::scenarios {

void AddCompareCommand(CLI::App& app, int& exit_code);

}  // namespace trimbot::scenarios
