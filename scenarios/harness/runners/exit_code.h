#pragma once
// The exit codes of the runners and of `trimbot` (README, `trimbot --help`):
//   0  success
//   1  a criterion or check failed (a trial missed its goal, a pair was not registered, ...)
//   2  bad input or usage: a file or argument that cannot be used, named in the message
//   3  internal error: a bug, reported with what was being done

namespace trimbot::scenarios {

enum ExitCode : int { kExitSuccess = 0, kExitCheckFailed = 1, kExitBadInput = 2, kExitInternalError = 3 };

}  // namespace trimbot::scenarios
