#include "runners/registration_cv.h"

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <limits>
#include <sstream>

#include "evaluation/pose_errors.h"
#include "evaluation/trial_result.h"

namespace trimbot::scenarios {
namespace {

struct Candidate {
  perception::RegistrationOptions options;
  std::string name;
};

std::vector<Candidate> Grid(const perception::RegistrationOptions& base) {
  std::vector<Candidate> grid;
  for (int neighbours : {6, 10, 16}) {
    for (double surface : {0.0, 4.0, 10.0}) {
      for (double outlier : {0.03, 0.1, 0.3}) {
        Candidate c{base, ""};
        c.options.method = perception::RegistrationMethod::kDugma;
        c.options.neighbours = neighbours;
        c.options.surface_spacings = surface;
        c.options.outlier_weight = outlier;
        std::ostringstream name;
        name << "k" << neighbours << " s" << surface << " w" << outlier;
        c.name = name.str();
        grid.push_back(c);
      }
    }
  }
  return grid;
}

struct Outcome {
  double rotation = 0.0, translation = 0.0, seconds = 0.0;
};

Outcome Run(const RegistrationPair& pair, const perception::RegistrationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const auto result = perception::Register(pair.x, pair.y, Eigen::Isometry3d::Identity(), ForPair(options, pair));
  return {RotationErrorDegrees(result.transform, pair.truth), TranslationError(result.transform, pair.truth),
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
}

// Lower is better: pairs at or over 5 deg first, then the median rotation error.
std::pair<int, double> Score(const std::vector<double>& rotations) {
  const int failures =
      static_cast<int>(std::count_if(rotations.begin(), rotations.end(), [](double r) { return r >= 5.0; }));
  return {failures, ErrorStats::From(rotations).median};
}

}  // namespace

std::vector<CrossValidationRow> CrossValidateDugma(const std::vector<RegistrationPair>& pairs, int folds,
                                                   const perception::RegistrationOptions& base, std::ostream& out) {
  const std::vector<Candidate> grid = Grid(base);
  // Every candidate on every pair once; the folds only choose among them.
  std::vector<std::vector<Outcome>> outcomes(grid.size());
  for (std::size_t c = 0; c < grid.size(); ++c) {
    for (const RegistrationPair& pair : pairs) outcomes[c].push_back(Run(pair, grid[c].options));
  }
  perception::RegistrationOptions icp = base;
  icp.method = perception::RegistrationMethod::kIcpPointToPoint;
  std::vector<CrossValidationRow> rows(pairs.size());
  for (int fold = 0; fold < folds; ++fold) {
    std::size_t best = 0;
    std::pair<int, double> best_score{std::numeric_limits<int>::max(), 0.0};
    for (std::size_t c = 0; c < grid.size(); ++c) {
      std::vector<double> training;
      for (std::size_t p = 0; p < pairs.size(); ++p) {
        if (static_cast<int>(p % folds) != fold) training.push_back(outcomes[c][p].rotation);
      }
      const auto score = Score(training);
      if (score < best_score) best_score = score, best = c;
    }
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      if (static_cast<int>(p % folds) != fold) continue;
      const Outcome& o = outcomes[best][p];
      rows[p] = {
          pairs[p].name, fold, grid[best].name, o.rotation, o.translation, o.seconds, Run(pairs[p], icp).rotation};
    }
  }
  out << std::left << std::setw(10) << "pair" << std::right << std::setw(5) << "fold" << std::setw(20) << "parameters"
      << std::setw(11) << "rot (deg)" << std::setw(11) << "trans (m)" << std::setw(10) << "time (s)" << std::setw(11)
      << "ICP (deg)"
      << "\n";
  std::vector<double> rotation, translation, seconds;
  int under_5 = 0, worse_than_icp = 0;
  for (const CrossValidationRow& row : rows) {
    out << std::left << std::setw(10) << row.pair << std::right << std::setw(5) << row.fold << std::setw(20)
        << row.parameters << std::fixed << std::setprecision(2) << std::setw(11) << row.rotation_deg
        << std::setprecision(3) << std::setw(11) << row.translation_m << std::setw(10) << row.seconds
        << std::setprecision(2) << std::setw(11) << row.icp_rotation_deg
        << (row.rotation_deg > row.icp_rotation_deg + 2.0 ? "  worse than ICP by > 2 deg" : "") << "\n";
    rotation.push_back(row.rotation_deg);
    translation.push_back(row.translation_m);
    seconds.push_back(row.seconds);
    under_5 += row.rotation_deg < 5.0 ? 1 : 0;
    worse_than_icp += row.rotation_deg > row.icp_rotation_deg + 2.0 ? 1 : 0;
  }
  out << std::fixed << std::setprecision(3) << "cross-validated (" << folds << " folds, " << grid.size()
      << " candidates, chosen without the fold): median rotation " << ErrorStats::From(rotation).median
      << " deg, translation " << ErrorStats::From(translation).median << " m, time " << ErrorStats::From(seconds).median
      << " s; " << under_5 << " of " << rows.size() << " under 5 deg; " << worse_than_icp
      << " worse than ICP by more than 2 deg\n";
  return rows;
}

}  // namespace trimbot::scenarios
