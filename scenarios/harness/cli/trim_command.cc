// `trimbot trim precompute` (runners/trim_precompute.h).
#include <memory>

#include "cli/command.h"
#include "runners/trim_precompute.h"

namespace trimbot::scenarios {

void AddTrimCommands(Commands& commands) {
  auto options = std::make_shared<TrimPrecomputeOptions>();
  auto* trim = commands.app().add_subcommand("trim", "trimming: cutting paths");
  trim->require_subcommand(1);
  auto* precompute = trim->add_subcommand(
      "precompute", "solve cutting paths for a grid of topiary shapes, sizes and placements and store them (SQLite)");
  precompute->add_option("--out", options->out, "the database file to write")->required();
  precompute->add_option("--shapes", options->shapes, "ball, cylinder, box")->delimiter(',');
  precompute->add_option("--sizes", options->sizes, "target widths, m")->delimiter(',');
  precompute->add_option("--distances", options->distances, "from base_link's origin to the target's centre, m")
      ->delimiter(',');
  precompute->add_option("--bearings", options->bearings_deg, "of the target's centre from ahead, deg")->delimiter(',');
  commands.OnRun(precompute, [options, &commands] { return RunTrimPrecompute(*options, commands.paths()); });
}

}  // namespace trimbot::scenarios
