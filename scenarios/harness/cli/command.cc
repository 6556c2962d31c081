#include "cli/command.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {
namespace {

bool NamesANonFiniteNumber(const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  return end != text.c_str() && !std::isfinite(value);
}

const CLI::Validator kFinite(
    [](std::string& text) {
      return NamesANonFiniteNumber(text) ? "'" + text + "' is not a finite number" : std::string();
    },
    "FINITE");

const CLI::Validator kNotNegative(
    [](std::string& text) {
      const auto first = text.find_first_not_of(" \t");
      return first != std::string::npos && text[first] == '-' ? "'" + text + "' must not be negative" : std::string();
    },
    "");

// The option's own type, without its validators' descriptions.
std::string TypeOf(const CLI::Option& option) {
  const std::string full = option.get_type_name();
  return full.substr(0, full.find(':'));
}

// Adds to every numeric option of `app` and its subcommands, whatever its own checks: floating
// point values must be finite (CLI11's Range lets NaN through, since NaN < lo is false), unsigned
// ones must not be negative (CLI11 would wrap -1 to 2^64 - 1). Call once all options exist.
void CheckEveryNumber(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string type = TypeOf(*option);
    if (type == "FLOAT") option->check(kFinite);
    if (type == "UINT") option->check(kNotNegative);
  }
  for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; })) CheckEveryNumber(*command);
}

// Parses argv; usage errors are printed and mapped to kExitBadInput, --help to kExitSuccess. An
// unknown command is named. Returns -1 when parsing succeeded and the command should run.
int ParseArguments(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
    return -1;
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help
    // "A subcommand is required" when the first word is a command that does not exist: name it.
    std::string known;
    bool is_known = false;
    for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
      known += (known.empty() ? "" : ", ") + command->get_name();
      is_known = is_known || (argc > 1 && command->get_name() == argv[1]);
    }
    if (argc > 1 && argv[1][0] != '-' && !is_known) {
      std::fprintf(stderr, "error: unknown command '%s' (commands: %s)\n", argv[1], known.c_str());
      return kExitBadInput;
    }
    app.exit(e);
    return kExitBadInput;
  }
}

}  // namespace

Commands::Commands(CLI::App& app) : app_(app), data_root_(ProjectPaths::Default().root) {
  app.add_option("--data-root", data_root_, "folder holding robot/, garden_scenes/ (default: the source tree)");
}

void Commands::OnRun(CLI::App* command, std::function<int()> run) { runs_.emplace_back(command, std::move(run)); }

int Commands::ParseAndRun(int argc, char** argv) {
  CheckEveryNumber(app_);
  try {
    if (const int parse_exit = ParseArguments(app_, argc, argv); parse_exit >= 0) return parse_exit;
    for (const auto& [command, run] : runs_) {
      if (command->parsed()) return run();
    }
    return kExitSuccess;  // a command group without a command of its own: CLI11 asked for one
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error: %s\n", e.what());
    return kExitInternalError;
  }
}

}  // namespace trimbot::scenarios
