#include "cli/compare_command.h"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "eval/comparison.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {
namespace {

// A batch summary: `path` is an output folder of `trimbot run` or a summary JSON file.
nlohmann::json ReadSummary(std::string* path) {
  if (std::filesystem::is_directory(*path)) *path += "/summary.json";
  std::ifstream in(*path);
  if (!in) throw InputError(*path, "not found (give an output folder of `trimbot run` or its summary.json)");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(*path, std::string("malformed JSON: ") + e.what());
  }
}

struct Options {
  std::string baseline, candidate, out;
  double alpha = 0.05;
};

int RunCompare(Options options) {
  const nlohmann::json baseline = ReadSummary(&options.baseline);
  const nlohmann::json candidate = ReadSummary(&options.candidate);
  const Comparison comparison = CompareBatches(baseline, options.baseline, candidate, options.candidate, options.alpha);
  const std::string markdown = ToMarkdown(comparison);
  std::cout << markdown;
  if (!options.out.empty()) {
    std::filesystem::create_directories(options.out);
    WriteFileAtomically(options.out + "/comparison.json", ToJson(comparison).dump(2));
    WriteFileAtomically(options.out + "/comparison.md", markdown);
    WriteFileAtomically(options.out + "/junit.xml", ToJunitXml(comparison));
  }
  return comparison.regressed ? 1 : 0;
}

}  // namespace

void AddCompareCommand(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<Options>();
  auto* command = app.add_subcommand(
      "compare", "test whether a batch is worse than a baseline beyond trial-to-trial noise (exit 1 if so)");
  command->add_option("baseline", options->baseline, "baseline: output folder of `trimbot run` or a summary.json")
      ->required();
  command->add_option("candidate", options->candidate, "candidate: output folder or summary.json")->required();
  command->add_option("--alpha", options->alpha, "false-alarm level over all metrics")->check(CLI::Range(1e-6, 0.5));
  command->add_option("--out", options->out, "write comparison.json, comparison.md and junit.xml here");
  command->callback([options, &exit_code]() { exit_code = RunCompare(*options); });
}

}  // namespace trimbot::scenarios
