#pragma once
// `trimbot register`: registration of point-cloud pairs in the DUGMA data set format, with a
// table of errors against the ground truth and the time per pair.
#include <CLI/CLI.hpp>

#include <Eigen/Geometry>
#include <string>

#include "eval/registration_pair_file.h"
#include "eval/registration_set.h"
#include "trimbot/perception/point_cloud.h"

namespace trimbot::scenarios {

void AddRegistrationCommand(CLI::App& app, int& exit_code);
// `trimbot register-set`: a rendered registration data set with known truth (eval/registration_set.h).
void AddRegistrationSetCommand(CLI::App& app, int& exit_code);

}  // namespace trimbot::scenarios
