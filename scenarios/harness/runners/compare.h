#pragma once
// `trimbot compare BASELINE CANDIDATE`: is the candidate batch worse than the baseline beyond
// trial-to-trial noise? (evaluation/comparison.h).
#include <string>

namespace trimbot::scenarios {

struct CompareOptions {
  std::string baseline, candidate;  // output folders of `trimbot run`, or their summary.json
  std::string out;                  // comparison.{json,md} and junit.xml go here (empty: none)
  double alpha = 0.05;              // false-alarm level over all metrics
};

// Prints the comparison as Markdown and writes the files; returns 1 on a regression, else 0.
int RunCompare(CompareOptions options);

}  // namespace trimbot::scenarios
