// `trimbot compare BASELINE CANDIDATE` (runners/compare.h). Exit code 1 on a regression.
#include <memory>

#include "cli/command.h"
#include "runners/compare.h"

namespace trimbot::scenarios {

void AddCompareCommand(Commands& commands) {
  auto options = std::make_shared<CompareOptions>();
  auto* command = commands.app().add_subcommand(
      "compare", "test whether a batch is worse than a baseline beyond trial-to-trial noise (exit 1 if so)");
  command->add_option("baseline", options->baseline, "baseline: output folder of `trimbot run` or a summary.json")
      ->required();
  command->add_option("candidate", options->candidate, "candidate: output folder or summary.json")->required();
  command->add_option("--alpha", options->alpha, "false-alarm level over all metrics")->check(CLI::Range(1e-6, 0.5));
  command->add_option("--out", options->out, "write comparison.json, comparison.md and junit.xml here");
  commands.OnRun(command, [options] { return RunCompare(*options); });
}

}  // namespace trimbot::scenarios
