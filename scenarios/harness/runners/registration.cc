#include "runners/registration.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>

#include "evaluation/pose_errors.h"
#include "evaluation/registration_set.h"
#include "evaluation/trial_result.h"
#include "runners/exit_code.h"
#include "runners/registration_cv.h"
#include "trimbot/common/input_error.h"
#include "trimbot/perception/registration.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;

double Median(const std::vector<double>& v) { return ErrorStats::From(v).median; }

perception::PointCloud EveryKth(const perception::PointCloud& cloud, int k) {
  if (k <= 1) return cloud;
  perception::PointCloud thinned;
  for (std::size_t i = 0; i < cloud.size(); i += static_cast<std::size_t>(k))
    thinned.Add(cloud.points[i], cloud.covariances[i]);
  return thinned;
}

RegistrationPair Thinned(RegistrationPair pair, int target_every, int source_every) {
  pair.x = EveryKth(pair.x, target_every);
  pair.y = EveryKth(pair.y, source_every);
  return pair;
}

// One row per pair (sizes, errors, time, the EM's state, the both-ways check) and the medians.
// Returns the number of pairs that could not be registered (too few usable points).
int RegisterEach(const std::vector<RegistrationPair>& pairs, const perception::RegistrationOptions& registration,
                 const std::string& method, bool show_starts, std::ostream& out) {
  out << std::left << std::setw(10) << "pair" << std::right << std::setw(8) << "|X|" << std::setw(8) << "|Y|"
      << std::setw(9) << "dropped" << std::setw(11) << "rot (deg)" << std::setw(11) << "trans (m)" << std::setw(7)
      << "iters" << std::setw(10) << "time (s)" << std::setw(9) << "matched" << std::setw(6) << "conv" << std::setw(9)
      << "cost" << std::setw(11) << "both ways" << std::setw(9) << "on surf"
      << "\n";
  std::vector<double> rotation, translation, seconds;
  int under_5_degrees = 0;
  int unregistered = 0;
  for (const RegistrationPair& pair : pairs) {
    const auto start = std::chrono::steady_clock::now();
    perception::RegistrationResult result;
    try {
      result = perception::Register(pair.x, pair.y, Eigen::Isometry3d::Identity(), ForPair(registration, pair));
    } catch (const perception::RegistrationError& e) {
      out << std::left << std::setw(10) << pair.name << "  not registered: " << e.what() << "\n";
      ++unregistered;
      continue;
    }
    const double time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double r = RotationErrorDegrees(result.transform, pair.truth);
    const double t = TranslationError(result.transform, pair.truth);
    rotation.push_back(r);
    translation.push_back(t);
    seconds.push_back(time);
    under_5_degrees += r < 5.0 ? 1 : 0;
    const int dropped =
        static_cast<int>(pair.x.size() + pair.y.size()) - result.target_points.kept - result.source_points.kept;
    out << std::left << std::setw(10) << pair.name << std::right << std::setw(8) << pair.x.size() << std::setw(8)
        << pair.y.size() << std::setw(9) << dropped << std::fixed << std::setprecision(2) << std::setw(11) << r
        << std::setprecision(3) << std::setw(11) << t << std::setw(7) << result.iterations << std::setw(10) << time
        << std::setprecision(2) << std::setw(9) << result.matched_fraction << std::setw(6) << result.converged
        << std::setw(9) << result.final_cost << std::setw(11) << result.consistency_deg << std::setw(9)
        << result.on_surface << (result.trusted ? "" : "  untrusted: " + result.doubt) << "\n";
    if (show_starts) {
      for (std::size_t k = 0; k < result.starts.size(); ++k) {
        const perception::RegistrationStart& start = result.starts[k];
        out << "    start " << k << (static_cast<int>(k) == result.chosen_start ? " (chosen)" : "") << ": rotation "
            << RotationErrorDegrees(start.transform, pair.truth) << " deg, translation "
            << TranslationError(start.transform, pair.truth) << " m, on surface " << start.on_surface
            << ", log-likelihood " << start.log_likelihood << "\n";
      }
    }
  }
  if (rotation.empty()) {
    out << "no pair registered (" << method << ")\n";
    return unregistered;
  }
  out << std::fixed << std::setprecision(3) << "median (" << method << ", " << rotation.size() << " pairs): rotation "
      << Median(rotation) << " deg, translation " << Median(translation) << " m, time " << Median(seconds)
      << " s (both ways); " << under_5_degrees << " of " << rotation.size() << " under 5 deg\n";
  return unregistered;
}

}  // namespace

namespace {

// The folder's pairs, each bad file reported on stderr and counted in `bad_files`.
std::vector<RegistrationPair> LoadPairFolder(const RegisterOptions& options, int* bad_files) {
  if (!fs::is_directory(options.folder)) throw InputError(options.folder, "not a folder");
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(options.folder)) {
    if (entry.path().extension() == ".txt") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(options.folder, "holds no .txt pair files");
  std::vector<RegistrationPair> pairs;
  for (const auto& file : files) {
    const std::string name = fs::path(file).stem().string();
    if (std::find(options.exclude.begin(), options.exclude.end(), name) != options.exclude.end()) continue;
    try {
      pairs.push_back(Thinned(LoadRegistrationPair(file), options.thin_target, options.thin_source));
    } catch (const InputError& e) {
      std::cerr << "error: " << e.what() << "\n";
      ++*bad_files;
    }
  }
  if (pairs.empty()) throw InputError(options.folder, "no usable pair left to register");
  return pairs;
}

}  // namespace

perception::RegistrationOptions FromTheIdentity() {
  perception::RegistrationOptions options;
  options.heading_search_deg = 45.0;
  return options;
}

int RunRegister(const RegisterOptions& options) {
  perception::RegistrationOptions registration = options.registration;
  registration.method = options.method == "icp"         ? perception::RegistrationMethod::kIcpPointToPoint
                        : options.method == "icp_plane" ? perception::RegistrationMethod::kIcpPointToPlane
                        : options.method == "gicp"      ? perception::RegistrationMethod::kGeneralizedIcp
                                                        : perception::RegistrationMethod::kDugma;
  registration.check_consistency = true;  // say which results are not to be trusted
  registration.max_variance = 1e5;        // the data set's 1e6 entries mark unusable points
  int bad_files = 0;
  const std::vector<RegistrationPair> pairs = LoadPairFolder(options, &bad_files);
  if (options.folds > static_cast<int>(pairs.size())) {
    throw InputError(options.folder, "fewer pairs than --cross-validate folds");
  }
  int unregistered = 0;
  if (options.folds > 0) {
    CrossValidateDugma(pairs, options.folds, registration, std::cout);
  } else {
    unregistered = RegisterEach(pairs, registration, options.method, options.show_starts, std::cout);
  }
  if (bad_files + unregistered > 0) {
    std::cerr << bad_files << " pair file(s) could not be read, " << unregistered
              << " pair(s) could not be registered\n";
  }
  return bad_files + unregistered > 0 ? kExitBadInput : kExitSuccess;
}

int RunRegistrationSet(const RegistrationSetOptions& options, const std::string& out, const ProjectPaths& paths) {
  fs::create_directories(out);
  const auto pairs = RenderRegistrationPairs(options, paths, out);
  for (const RegistrationPair& pair : pairs) WriteRegistrationPair(out + "/" + pair.name + ".txt", pair);
  std::cout << pairs.size() << " pairs in " << out << " (register them: trimbot register " << out << ")\n";
  return pairs.size() == static_cast<std::size_t>(options.pairs) ? 0 : 1;
}

}  // namespace trimbot::scenarios
