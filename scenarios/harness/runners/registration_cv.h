#pragma once
// Cross-validated DUGMA on pairs with ground truth (`trimbot register --cross-validate K`): the
// parameters are chosen on K-1 folds of the pairs and reported on the fold left out, so no pair's
// error comes from parameters fitted to it. Every pair is reported with its fold, the parameters
// chosen without it, its errors, and Open3D's ICP on the same pair.
#include <ostream>
#include <string>
#include <vector>

#include "evaluation/registration_pair_file.h"
#include "trimbot/perception/registration.h"

namespace trimbot::scenarios {

struct CrossValidationRow {
  std::string pair;
  int fold = 0;
  std::string parameters;  // chosen on the other folds
  double rotation_deg = 0.0, translation_m = 0.0, seconds = 0.0;
  double icp_rotation_deg = 0.0;  // Open3D point-to-point ICP, same pair
};

// `base`: the options every candidate starts from (method DUGMA); the grid varies neighbours,
// surface_spacings and outlier_weight. Writes the table and summary to `out`; returns the rows.
std::vector<CrossValidationRow> CrossValidateDugma(const std::vector<RegistrationPair>& pairs, int folds,
                                                   const perception::RegistrationOptions& base, std::ostream& out);

}  // namespace trimbot::scenarios
