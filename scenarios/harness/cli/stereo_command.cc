// `trimbot stereo` (runners/stereo_frame.h).
#include <memory>

#include "cli/command.h"
#include "runners/stereo_frame.h"

namespace trimbot::scenarios {

void AddStereoCommand(Commands& commands) {
  auto options = std::make_shared<StereoFrameOptions>();
  auto* command = commands.app().add_subcommand(
      "stereo", "stereo depth of one rendered ring frame: errors against ground truth, disparity images, cloud");
  command->add_option("--garden", options->garden, "garden name or file")->required();
  command->add_option("--out", options->output, "output folder")->required();
  command->add_flag("--dense", options->dense, "64 disparities, 8-path SGM (quality) instead of the robot's 32");
  command->add_option("--seed", options->seed, "seed of textures, foliage and image noise");
  command->add_option("--x", options->x, "robot position in the map (m)")->check(CLI::Range(-1e4, 1e4));
  command->add_option("--y", options->y, "robot position in the map (m)")->check(CLI::Range(-1e4, 1e4));
  command->add_option("--yaw-deg", options->yaw_degrees, "robot heading in the map (degrees)")
      ->check(CLI::Range(-3600.0, 3600.0));
  command->add_option("--stride", options->stride, "use every n-th pixel for the cloud")->check(CLI::Range(1, 16));
  commands.OnRun(command, [options, &commands] { return RunStereoFrame(*options, commands.paths()); });
}

}  // namespace trimbot::scenarios
