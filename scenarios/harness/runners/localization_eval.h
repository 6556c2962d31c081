#pragma once
// Offline evaluation of visual localization against a map, on ring frames rendered along a query
// drive (a drive plan, possibly at other conditions, another seed, shifted sideways): the
// stack's own localizer (robot/config/stack.yaml's visual_localization, with --set overrides),
// compared with the simulator's ground truth.
//   trimbot map bench           per frame: fix or not, errors, the fix NEES against its stated
//                               covariance (localization_frames.csv), time by stage (median, p90); the
//                               processing-time histogram (D3.4 Figure 10)
//   trimbot map retrieval-eval  D3.4 Table 4: the share of the top-5 (--top) retrieved keyframes with at
//                               least 50 / 100 / 200 geometrically verified matches, per image and
//                               per rig, for retrieval by vocabulary, by pose prior and combined
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loop/setting.h"

namespace trimbot::scenarios {

struct QueryDriveOptions {
  std::string plan_path;              // drive plan (YAML)
  std::optional<std::uint64_t> seed;  // default: the plan's + 2000 (other noise than a map's drive)
  std::optional<double> time_of_day;  // h; default: the plan's
  std::optional<int> day_of_year;
  std::optional<double> growth;
  double lateral_offset = 0.0;             // m: the start moved to the left of its heading
  std::optional<double> seconds;           // stop the drive early
  double interval = 1.0;                   // s of simulated time between query frames
  std::optional<double> resolution_scale;  // default: what the stack asks for (its image_scale)
  int msaa_samples = 4;                    // the renderer's anti-aliasing (as the trials render)
};

struct LocalizationEvalOptions {
  std::string map_path;
  QueryDriveOptions drive;
  std::vector<std::string> stack_overrides;  // key=value under stack.yaml, e.g. visual_localization.cameras=left
  double prior_sigma = 0.2;                  // m: the pose prior is the true position plus this noise
  int retrieval_top = 5;                     // retrieval-eval: keyframes retrieved per query (Table 4: 5)
  std::string out_dir;
  ProjectPaths paths;
};

// Writes localization_bench.json, localization_frames.csv and localization_time.png into out_dir;
// returns the exit code.
int RunLocalizationBench(const LocalizationEvalOptions& options);
// Writes retrieval_eval.json into out_dir and prints the table; returns the exit code.
int RunRetrievalEval(const LocalizationEvalOptions& options);

}  // namespace trimbot::scenarios
