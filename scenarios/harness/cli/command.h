#pragma once
// How every `trimbot` command is registered and run, and what all share about arguments and exit
// codes. A command file adds its subcommands with their options, and for each the function that
// runs it once the arguments are parsed; that function calls a runner and returns the exit code:
//   void AddFusionCommand(Commands& commands) {
//     auto options = std::make_shared<FusionDriveOptions>();
//     CLI::App* fusion = commands.app().add_subcommand("fusion", "...");
//     fusion->add_option("plan", options->plan)->required();
//     commands.OnRun(fusion, [options, &commands] { return RunFusionDrive(*options, commands.paths()); });
//   }
//
#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

#include "loop/setting.h"
#include "runners/exit_code.h"

namespace trimbot::scenarios {

// The app's commands and the function that runs each.
class Commands {
 public:
  // Adds the global --data-root option to `app`.
  explicit Commands(CLI::App& app);
  CLI::App& app() { return app_; }
  // The project's data files; --data-root's, so read it only once the arguments are parsed.
  ProjectPaths paths() const { return {data_root_}; }
  // `run` runs `command` when the arguments named it; it returns the exit code.
  void OnRun(CLI::App* command, std::function<int()> run);
  // Parses argv and runs the command it named; returns the exit code. Bad input
  // (InputError) is printed and gives kExitBadInput, any other exception kExitInternalError.
  int ParseAndRun(int argc, char** argv);

 private:
  CLI::App& app_;
  std::string data_root_;
  std::vector<std::pair<CLI::App*, std::function<int()>>> runs_;
};

// The commands, in the order `trimbot --help` lists them (one file each in cli/).
void AddDriveCommand(Commands& commands);
void AddBenchCommand(Commands& commands);
void AddGardenCommands(Commands& commands);        // garden import-csv | generate | export
void AddBatchCommands(Commands& commands);         // run, suite, merge
void AddRegistrationCommands(Commands& commands);  // register, register-set
void AddCompareCommand(Commands& commands);
void AddTuningCommands(Commands& commands);  // sweep, tune, ablate
void AddMapCommands(Commands& commands);     // map build | ensure | bench | retrieval-eval
void AddFusionCommand(Commands& commands);
void AddStereoCommand(Commands& commands);
void AddTrimCommands(Commands& commands);  // trim precompute
void AddReportCommand(Commands& commands);

}  // namespace trimbot::scenarios
