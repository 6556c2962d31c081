#pragma once
// `trimbot register`: registration of point-cloud pairs in the DUGMA data set format, with a
// table of errors against the ground truth and the time per pair.
#include <CLI/CLI.hpp>

#include <Eigen/Geometry>
#include <string>

#include "eval/registration_set.h"
#include "trimbot/perception/point_cloud.h"

namespace trimbot::scenarios {

// A pair file: `R r00 .. r22` and `t tx ty tz` (ground truth x = R y + t), then blocks `X n` and
// `Y m` of lines `x y z c00 c01 c02 c11 c12 c22`; `#` starts a comment. Throws InputError naming
// the file and line.
RegistrationPair LoadRegistrationPair(const std::string& path);

void AddRegistrationCommand(CLI::App& app, int& exit_code);
// `trimbot register-set`: a rendered registration data set with known truth (eval/registration_set.h).
void AddRegistrationSetCommand(CLI::App& app, int& exit_code);

}  // namespace trimbot::scenarios
