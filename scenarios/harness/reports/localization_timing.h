#pragma once
// Processing time of visual localization per ring frame, split by stage (features, retrieval,
// matching, pose): statistics for timing.json and the histogram of the reference deliverable's
// Figure 10. Wall-clock figures: kept out of the reproducible results.
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "trimbot/visual_localization/localizer.h"

namespace trimbot::scenarios {

// {"frames": n, "<stage>": {"mean_ms", "median_ms", "p90_ms", "max_ms"}, ...} for the stages and
// their total, and each frame's stages in "frames_ms" ([features, retrieval, matching, pose]).
nlohmann::json LocalizationTimeStats(const std::vector<visual_localization::LocalizationTimings>& frames);
// The frames back from LocalizationTimeStats' "frames_ms" (none when absent).
std::vector<visual_localization::LocalizationTimings> LocalizationTimesFromJson(const nlohmann::json& stats);

// Histogram of the per-frame total (ms), each bar split by the stages' mean shares of the frames in
// it, with the median per stage in the legend. Writes the PNG atomically.
void WriteLocalizationTimeHistogram(const std::string& path, const std::string& title,
                                    const std::vector<visual_localization::LocalizationTimings>& frames);

}  // namespace trimbot::scenarios
