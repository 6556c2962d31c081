// `trimbot drive PLAN` (runners/drive.h) and `trimbot bench` (runners/bench.h).
#include <memory>

#include "cli/command.h"
#include "runners/bench.h"
#include "runners/drive.h"

namespace trimbot::scenarios {

void AddDriveCommand(Commands& commands) {
  auto options = std::make_shared<DriveOptions>();
  auto seed = std::make_shared<std::uint64_t>(0);
  auto seconds = std::make_shared<double>(0.0);
  auto no_cameras = std::make_shared<bool>(false);
  auto* drive =
      commands.app().add_subcommand("drive", "drive the robot headless through a drive plan and record everything");
  drive->add_option("plan", options->plan_path, "drive plan (YAML)")->required();
  drive->add_option("--out", options->output_dir, "output folder")->required();
  auto* seed_option = drive->add_option("--seed", *seed, "noise seed (default: the plan's)");
  auto* seconds_option =
      drive->add_option("--seconds", *seconds, "stop after this much simulated time")->check(CLI::Range(1e-3, 1e6));
  drive->add_option("--calibration", options->calibration_path, "camera calibration (Kalibr camchain)");
  drive->add_option("--resolution-scale", options->resolution_scale, "render at this fraction of 752x480")
      ->check(CLI::Range(0.1, 1.0));
  drive->add_option("--msaa", options->msaa_samples, "anti-aliasing samples (0: twice as fast, jagged edges)")
      ->check(CLI::Range(0, 16));
  drive->add_flag("--no-cameras", *no_cameras, "do not render the ring");
  drive->add_flag("--quiet", options->quiet, "no progress display");
  drive->add_flag("--video", options->video, "write drive.mp4: a camera following the robot, cam0 and a top view");
  commands.OnRun(drive, [=, &commands] {
    options->paths = commands.paths();
    if (seed_option->count() > 0) options->seed = *seed;
    if (seconds_option->count() > 0) options->seconds = *seconds;
    options->cameras = !*no_cameras;
    return RunDrive(*options);
  });
}

void AddBenchCommand(Commands& commands) {
  auto options = std::make_shared<BenchOptions>();
  auto* bench = commands.app().add_subcommand("bench", "measure rendering cost, physics speed and real-time factor");
  bench->add_option("--garden", options->garden, "garden name or file");
  bench->add_option("--out", options->output_path, "write the report as JSON here");
  bench->add_option("--frames", options->frames, "ring frames per measurement")->check(CLI::Range(1, 100000));
  bench->add_option("--drive-seconds", options->drive_seconds, "simulated seconds of the drive measurement")
      ->check(CLI::Range(1e-3, 1e5));
  commands.OnRun(bench, [options, &commands] {
    options->paths = commands.paths();
    return RunBench(*options);
  });
}

}  // namespace trimbot::scenarios
