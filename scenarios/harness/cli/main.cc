// trimbot: the digital twin's command-line tool. The commands only parse arguments and call the
// runners (runners/); see cli/command.h.
#include <CLI/CLI.hpp>

#include "cli/command.h"

int main(int argc, char** argv) {
  using namespace trimbot::scenarios;
  CLI::App app{"trimbot - simulation-backed digital twin of the TrimBot2020 garden robot"};
  app.footer(
      "Exit codes: 0 success; 1 a criterion or check failed; 2 bad input or usage (the file, key or argument is "
      "named); 3 internal error.");
  app.require_subcommand(1);
  Commands commands(app);
  AddDriveCommand(commands);
  AddBenchCommand(commands);
  AddGardenCommands(commands);
  AddBatchCommands(commands);
  AddRegistrationCommands(commands);
  AddCompareCommand(commands);
  AddTuningCommands(commands);
  AddMapCommands(commands);
  AddFusionCommand(commands);
  AddStereoCommand(commands);
  AddTrimCommands(commands);
  AddReportCommand(commands);
  return commands.ParseAndRun(argc, argv);
}
