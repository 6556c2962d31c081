// trimbot: the digital twin's command-line tool.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "cli/batch_command.h"
#include "cli/bench_command.h"
#include "cli/cli_checks.h"
#include "cli/compare_command.h"
#include "cli/drive_command.h"
#include "cli/fusion_command.h"
#include "cli/garden_command.h"
#include "cli/map_command.h"
#include "cli/registration_command.h"
#include "cli/stereo_command.h"
#include "cli/tuning_commands.h"
#include "trimbot/common/input_error.h"

int main(int argc, char** argv) {
  using namespace trimbot::scenarios;
  CLI::App app{"trimbot - simulation-backed digital twin of the TrimBot2020 garden robot"};
  app.footer(
      "Exit codes: 0 success; 1 a criterion or check failed; 2 bad input or usage (the file, key or argument is "
      "named); 3 internal error.");
  app.require_subcommand(1);
  std::string data_root = ProjectPaths::Default().root;
  app.add_option("--data-root", data_root, "folder holding robot/, garden_scenes/ (default: the source tree)");

  DriveOptions drive;
  auto* drive_cmd = app.add_subcommand("drive", "drive the robot headless through a drive plan and record everything");
  drive_cmd->add_option("plan", drive.plan_path, "drive plan (YAML)")->required();
  drive_cmd->add_option("--out", drive.output_dir, "output folder")->required();
  std::uint64_t seed = 0;
  auto* seed_option = drive_cmd->add_option("--seed", seed, "noise seed (default: the plan's)");
  double seconds = 0.0;
  auto* seconds_option = drive_cmd->add_option("--seconds", seconds, "stop after this much simulated time")
                             ->check(CLI::Range(1e-3, 1e6));
  drive_cmd->add_option("--calibration", drive.calibration_path, "camera calibration (Kalibr camchain)");
  drive_cmd->add_option("--resolution-scale", drive.resolution_scale, "render at this fraction of 752x480")
      ->check(CLI::Range(0.1, 1.0));
  drive_cmd->add_option("--msaa", drive.msaa_samples, "anti-aliasing samples (0: twice as fast, jagged edges)")
      ->check(CLI::Range(0, 16));
  bool no_cameras = false;
  drive_cmd->add_flag("--no-cameras", no_cameras, "do not render the ring");
  drive_cmd->add_flag("--quiet", drive.quiet, "no progress display");

  BenchOptions bench;
  auto* bench_cmd = app.add_subcommand("bench", "measure rendering cost, physics speed and real-time factor");
  bench_cmd->add_option("--garden", bench.garden, "garden name or file");
  bench_cmd->add_option("--out", bench.output_path, "write the report as JSON here");
  bench_cmd->add_option("--frames", bench.frames, "ring frames per measurement")->check(CLI::Range(1, 100000));
  bench_cmd->add_option("--drive-seconds", bench.drive_seconds, "simulated seconds of the drive measurement")
      ->check(CLI::Range(1e-3, 1e5));

  AddGardenCommands(app, data_root);
  int exit_code = 0;
  AddBatchCommands(app, data_root, exit_code);
  AddRegistrationCommand(app, exit_code);
  AddRegistrationSetCommand(app, exit_code);
  AddCompareCommand(app, exit_code);
  AddTuningCommands(app, data_root, exit_code);
  AddMapCommands(app, data_root, exit_code);
  AddFusionCommand(app, data_root, exit_code);
  AddStereoCommand(app, data_root);

  CheckEveryNumber(app);

  try {
    if (const int parse_exit = ParseArguments(app, argc, argv); parse_exit >= 0) return parse_exit;
    if (drive_cmd->parsed()) {
      drive.paths = {data_root};
      if (seed_option->count() > 0) drive.seed = seed;
      if (seconds_option->count() > 0) drive.seconds = seconds;
      drive.cameras = !no_cameras;
      return RunDrive(drive);
    }
    if (bench_cmd->parsed()) {
      bench.paths = {data_root};
      return RunBench(bench);
    }
    return exit_code;
  } catch (const trimbot::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error: %s\n", e.what());
    return kExitInternalError;
  }
}
