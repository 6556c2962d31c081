#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "loop/setting.h"

namespace trimbot::scenarios {

struct DriveOptions {
  std::string plan_path;
  std::string output_dir;
  std::optional<std::uint64_t> seed;  // overrides the plan's seed
  std::optional<double> seconds;      // stop early
  std::string calibration_path;       // empty: the nominal calibration
  double resolution_scale = 1.0;
  int msaa_samples = 4;
  bool cameras = true;
  bool quiet = false;
  bool video = false;  // drive.mp4 beside the log (reports/trial_video.h)
  ProjectPaths paths;
};

// Runs a headless drive and writes its outputs; returns the process exit code.
int RunDrive(const DriveOptions& options);

}  // namespace trimbot::scenarios
