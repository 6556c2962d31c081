// `trimbot fusion PLAN` (runners/fusion_drive.h).
#include <memory>

#include "cli/command.h"
#include "runners/fusion_drive.h"

namespace trimbot::scenarios {

void AddFusionCommand(Commands& commands) {
  auto options = std::make_shared<FusionDriveOptions>();
  auto* command = commands.app().add_subcommand(
      "fusion", "register consecutive 360-degree stereo clouds of a drive (DUGMA from the odometry guess)");
  command->add_option("plan", options->plan, "drive plan (YAML)")->required();
  command->add_option("--out", options->out, "output folder")->required();
  command->add_option("--interval", options->fusion.interval, "seconds between clouds")->check(CLI::Range(1e-3, 1e4));
  command->add_option("--clouds", options->clouds, "number of registrations")->check(CLI::Range(1, 10000));
  command->add_option("--stride", options->fusion.stride, "pixel stride of the stereo clouds")
      ->check(CLI::Range(1, 64));
  command->add_option("--ground-keep", options->fusion.ground_keep, "fraction of ground points kept")
      ->check(CLI::Range(0.0, 1.0));
  commands.OnRun(command, [options, &commands] { return RunFusionDrive(*options, commands.paths()); });
}

}  // namespace trimbot::scenarios
