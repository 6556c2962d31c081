#include "cli/registration_command.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <set>
#include <sstream>

#include "eval/pose_errors.h"
#include "cli/cli_checks.h"
#include "cli/registration_cv.h"
#include "eval/registration_set.h"
#include "eval/trial_result.h"
#include "trimbot/common/input_error.h"
#include "trimbot/perception/registration.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;

double Median(const std::vector<double>& v) { return ErrorStats::From(v).median; }

perception::PointCloud EveryKth(const perception::PointCloud& cloud, int k) {
  if (k <= 1) return cloud;
  perception::PointCloud thinned;
  for (std::size_t i = 0; i < cloud.size(); i += static_cast<std::size_t>(k)) thinned.Add(cloud.points[i], cloud.covariances[i]);
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
      << "cost" << std::setw(11) << "both ways" << std::setw(9) << "on surf" << "\n";
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
        << std::setw(9) << result.final_cost << std::setw(11) << result.consistency_deg
        << std::setw(9) << result.on_surface << (result.trusted ? "" : "  untrusted: " + result.doubt) << "\n";
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

// The pairs are registered from the identity, so the guess's heading may be off by as much as the
// views turn: 10-43 deg in both the DUGMA data set and the rendered set.
perception::RegistrationOptions FromTheIdentity() {
  perception::RegistrationOptions options;
  options.heading_search_deg = 45.0;
  return options;
}

struct RegisterOptions {
  std::string folder;
  std::string method = "dugma";
  std::vector<std::string> exclude;
  int folds = 0;
  int thin_target = 1, thin_source = 1;
  bool show_starts = false;
  perception::RegistrationOptions registration = FromTheIdentity();
};

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

// A bad pair file is reported and the others are still registered; the exit code says so.
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
    std::cerr << bad_files << " pair file(s) could not be read, " << unregistered << " pair(s) could not be registered\n";
  }
  return bad_files + unregistered > 0 ? kExitBadInput : kExitSuccess;
}

}  // namespace

void AddRegistrationCommand(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<RegisterOptions>();
  auto* command = app.add_subcommand(
      "register", "register point-cloud pairs (DUGMA data set format) and report errors against ground truth");
  command->add_option("folder", options->folder, "folder of pair_NN.txt files")->required();
  command->add_option("--method", options->method,
                      "dugma, or a baseline by Open3D: icp (point-to-point), icp_plane (point-to-plane), gicp "
                      "(generalized ICP)")
      ->check(CLI::IsMember({"dugma", "icp", "icp_plane", "gicp"}));
  command->add_option("--exclude", options->exclude, "pair names to leave out (e.g. pair_26)");
  command->add_option("--thin-target", options->thin_target,
                      "keep every K-th point of X (how registration holds up on sparse clouds)")
      ->check(CLI::Range(1, 1000));
  command->add_option("--thin-source", options->thin_source, "keep every K-th point of Y")->check(CLI::Range(1, 1000));
  command->add_option("--cross-validate", options->folds,
                      "K: choose DUGMA's parameters on K-1 folds of the pairs, report each pair from its own fold")
      ->check(CLI::Range(2, 1000));
  auto& r = options->registration;
  command->add_option("--iterations", r.max_iterations, "most EM / ICP iterations")->check(CLI::Range(1, 100000));
  command->add_option("--neighbours", r.neighbours, "target points per source point (DUGMA)")->check(CLI::Range(1, 64));
  command->add_option("--anneal-start", r.anneal_start, "initial spread in m (<0: from the misalignment)")
      ->check(CLI::Range(-1.0, 10.0));
  command->add_option("--anneal-factor", r.anneal_factor, "spread factor per iteration")->check(CLI::Range(0.1, 0.99));
  command->add_option("--surface-spacings", r.surface_spacings,
                      "spread along the surface, in point spacings (DUGMA; 0: covariances as given)")
      ->check(CLI::Range(0.0, 1000.0));
  command->add_option("--heading-search", r.heading_search_deg,
                      "deg: DUGMA also starts turned about the ground's normal within this range of the guess (0: "
                      "one start)")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  command->add_option("--heading-step", r.heading_step_deg, "deg between the heading starts")
      ->check(CLI::Range(1.0, 90.0))
      ->capture_default_str();
  command->add_flag("--show-starts", options->show_starts, "print each DUGMA start's errors and fit");
  command->add_option("--outlier-weight", r.outlier_weight, "weight of the outlier term")->check(CLI::Range(0.0, 1e6));
  command->callback([options, &exit_code]() { exit_code = RunRegister(*options); });
}

void AddRegistrationSetCommand(CLI::App& app, int& exit_code) {
  struct Options {
    RegistrationSetOptions set;
    std::string out;
  };
  auto options = std::make_shared<Options>();
  auto* command = app.add_subcommand(
      "register-set", "render registration pairs with known truth from the twin (Kinect-like depth views of the "
                      "garden's bushes and objects from two viewpoints), in the DUGMA data set format");
  command->add_option("--garden", options->set.garden, "garden name or file")->capture_default_str();
  command->add_option("--pairs", options->set.pairs, "pairs to render")->check(CLI::Range(1, 10000))->capture_default_str();
  command->add_option("--seed", options->set.seed, "viewpoints and noise")->capture_default_str();
  command->add_option("--crop-margin", options->set.crop_margin,
                      "m of ground kept around the object (as in the DUGMA set); < 0 keeps the whole view")
      ->capture_default_str();
  command->add_option("--out", options->out, "folder for render_NNN.txt")->required();
  command->callback([options, &exit_code]() {
    fs::create_directories(options->out);
    const auto pairs = RenderRegistrationPairs(options->set, ProjectPaths::Default(), options->out);
    for (const RegistrationPair& pair : pairs) WriteRegistrationPair(options->out + "/" + pair.name + ".txt", pair);
    std::cout << pairs.size() << " pairs in " << options->out << " (register them: trimbot register " << options->out
              << ")\n";
    exit_code = pairs.size() == static_cast<std::size_t>(options->set.pairs) ? 0 : 1;
  });
}

}  // namespace trimbot::scenarios
