#pragma once
// What every `trimbot` command shares about its arguments and its exit code.
//
// Exit codes (README, `trimbot --help`):
//   0  success
//   1  a criterion or check failed (a trial missed its goal, a pair was not registered, ...)
//   2  bad input or usage: a file or argument that cannot be used, named in the message
//   3  internal error: a bug, reported with what was being done
#include <CLI/CLI.hpp>

namespace trimbot::scenarios {

enum ExitCode : int { kExitSuccess = 0, kExitCheckFailed = 1, kExitBadInput = 2, kExitInternalError = 3 };

// Adds to every numeric option of `app` and its subcommands, whatever its own checks: floating
// point values must be finite (CLI11's Range lets NaN through, since NaN < lo is false), unsigned
// ones must not be negative (CLI11 would wrap -1 to 2^64 - 1). Call once all options exist.
void CheckEveryNumber(CLI::App& app);

// Parses argv; usage errors are printed and mapped to kExitBadInput, --help to kExitSuccess. An
// unknown command is named. Returns -1 when parsing succeeded and the command should run.
int ParseArguments(CLI::App& app, int argc, char** argv);

}  // namespace trimbot::scenarios
