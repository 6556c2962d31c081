#include "runners/compare.h"

#include <filesystem>
#include <fstream>
#include <iostream>

#include "evaluation/comparison.h"
#include "reports/html_report.h"
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

}  // namespace

int RunCompare(CompareOptions options) {
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
    WriteHtmlReport(options.out);
  }
  return comparison.regressed ? 1 : 0;
}

}  // namespace trimbot::scenarios
