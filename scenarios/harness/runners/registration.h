#pragma once
// `trimbot register`: registration of point-cloud pairs in the DUGMA data set format, with a
// table of errors against the ground truth and the time per pair; `trimbot register-set`: such
// pairs rendered from the twin (evaluation/registration_set.h).
#include <string>
#include <vector>

#include "evaluation/registration_set.h"
#include "loop/setting.h"
#include "trimbot/perception/registration.h"

namespace trimbot::scenarios {

// The pairs are registered from the identity, so the guess's heading may be off by as much as the
// views turn: 10-43 deg in both the DUGMA data set and the rendered set.
perception::RegistrationOptions FromTheIdentity();

struct RegisterOptions {
  std::string folder;                    // of pair_NN.txt files
  std::string method = "dugma";          // or an Open3D baseline: icp, icp_plane, gicp
  std::vector<std::string> exclude;      // pair names left out
  int folds = 0;                         // > 0: cross-validated DUGMA (runners/registration_cv.h)
  int thin_target = 1, thin_source = 1;  // keep every K-th point
  bool show_starts = false;              // print each DUGMA start
  perception::RegistrationOptions registration = FromTheIdentity();
};

// Prints a row per pair and the medians. A bad pair file is reported and the others are still
// registered; returns 2 if a file could not be read or a pair not registered, else 0.
int RunRegister(const RegisterOptions& options);

// Renders `options.pairs` pairs into `out` (render_NNN.txt); returns 1 if fewer could be made.
int RunRegistrationSet(const RegistrationSetOptions& options, const std::string& out, const ProjectPaths& paths);

}  // namespace trimbot::scenarios
