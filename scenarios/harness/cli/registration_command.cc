// `trimbot register FOLDER` and `trimbot register-set` (runners/registration.h).
#include <memory>

#include "cli/command.h"
#include "runners/registration.h"

namespace trimbot::scenarios {
namespace {

void AddRegisterCommand(Commands& commands) {
  auto options = std::make_shared<RegisterOptions>();
  auto* command = commands.app().add_subcommand(
      "register", "register point-cloud pairs (DUGMA data set format) and report errors against ground truth");
  command->add_option("folder", options->folder, "folder of pair_NN.txt files")->required();
  command
      ->add_option("--method", options->method,
                   "dugma, or a baseline by Open3D: icp (point-to-point), icp_plane (point-to-plane), gicp "
                   "(generalized ICP)")
      ->check(CLI::IsMember({"dugma", "icp", "icp_plane", "gicp"}));
  command->add_option("--exclude", options->exclude, "pair names to leave out (e.g. pair_26)");
  command
      ->add_option("--thin-target", options->thin_target,
                   "keep every K-th point of X (how registration holds up on sparse clouds)")
      ->check(CLI::Range(1, 1000));
  command->add_option("--thin-source", options->thin_source, "keep every K-th point of Y")->check(CLI::Range(1, 1000));
  command
      ->add_option("--cross-validate", options->folds,
                   "K: choose DUGMA's parameters on K-1 folds of the pairs, report each pair from its own fold")
      ->check(CLI::Range(2, 1000));
  auto& r = options->registration;
  command->add_option("--iterations", r.max_iterations, "most EM / ICP iterations")->check(CLI::Range(1, 100000));
  command->add_option("--neighbours", r.neighbours, "target points per source point (DUGMA)")->check(CLI::Range(1, 64));
  command->add_option("--anneal-start", r.anneal_start, "initial spread in m (<0: from the misalignment)")
      ->check(CLI::Range(-1.0, 10.0));
  command->add_option("--anneal-factor", r.anneal_factor, "spread factor per iteration")->check(CLI::Range(0.1, 0.99));
  command
      ->add_option("--surface-spacings", r.surface_spacings,
                   "spread along the surface, in point spacings (DUGMA; 0: covariances as given)")
      ->check(CLI::Range(0.0, 1000.0));
  command
      ->add_option("--heading-search", r.heading_search_deg,
                   "deg: DUGMA also starts turned about the ground's normal within this range of the guess (0: "
                   "one start)")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  command->add_option("--heading-step", r.heading_step_deg, "deg between the heading starts")
      ->check(CLI::Range(1.0, 90.0))
      ->capture_default_str();
  command->add_flag("--show-starts", options->show_starts, "print each DUGMA start's errors and fit");
  command->add_option("--outlier-weight", r.outlier_weight, "weight of the outlier term")->check(CLI::Range(0.0, 1e6));
  commands.OnRun(command, [options] { return RunRegister(*options); });
}

void AddRegistrationSetCommand(Commands& commands) {
  struct Options {
    RegistrationSetOptions set;
    std::string out;
  };
  auto options = std::make_shared<Options>();
  auto* command = commands.app().add_subcommand(
      "register-set",
      "render registration pairs with known truth from the twin (Kinect-like depth views of the "
      "garden's bushes and objects from two viewpoints), in the DUGMA data set format");
  command->add_option("--garden", options->set.garden, "garden name or file")->capture_default_str();
  command->add_option("--pairs", options->set.pairs, "pairs to render")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  command->add_option("--seed", options->set.seed, "viewpoints and noise")->capture_default_str();
  command
      ->add_option("--crop-margin", options->set.crop_margin,
                   "m of ground kept around the object (as in the DUGMA set); < 0 keeps the whole view")
      ->capture_default_str();
  command->add_option("--out", options->out, "folder for render_NNN.txt")->required();
  commands.OnRun(command,
                 [options, &commands] { return RunRegistrationSet(options->set, options->out, commands.paths()); });
}

}  // namespace

void AddRegistrationCommands(Commands& commands) {
  AddRegisterCommand(commands);
  AddRegistrationSetCommand(commands);
}

}  // namespace trimbot::scenarios
