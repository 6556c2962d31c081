#pragma once
#include <string>

#include "loop/setting.h"

namespace trimbot::scenarios {

struct BenchOptions {
  std::string garden = "test_lawn";
  std::string output_path;  // JSON report
  int frames = 5;           // ring frames per rendering measurement
  double drive_seconds = 10.0;
  ProjectPaths paths;
};

// Measures rendering cost, physics speed and the real-time factor of a headless drive.
int RunBench(const BenchOptions& options);

}  // namespace trimbot::scenarios
