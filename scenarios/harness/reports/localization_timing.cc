#include "reports/localization_timing.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "evaluation/statistics.h"
#include "evaluation/trial_result.h"
#include "reports/drawing.h"
#include "reports/output_files.h"

namespace trimbot::scenarios {
namespace {

using visual_localization::LocalizationTimings;

constexpr std::array<const char*, 4> kStages = {"features", "retrieval", "matching", "pose"};

std::array<double, 4> StageSeconds(const LocalizationTimings& t) {
  return {t.features, t.retrieval, t.matching, t.pose};
}
double TotalSeconds(const LocalizationTimings& t) { return t.features + t.retrieval + t.matching + t.pose; }

nlohmann::json Stats(const std::vector<double>& ms) {
  const ErrorStats s = ErrorStats::From(ms);
  return {{"mean_ms", s.mean}, {"median_ms", s.median}, {"p90_ms", Percentile(ms, 0.9)}, {"max_ms", s.max}};
}

}  // namespace

nlohmann::json LocalizationTimeStats(const std::vector<LocalizationTimings>& frames) {
  nlohmann::json out = {{"frames", frames.size()}};
  std::vector<double> total;
  for (const auto& f : frames) total.push_back(1000.0 * TotalSeconds(f));
  for (std::size_t s = 0; s < kStages.size(); ++s) {
    std::vector<double> ms;
    for (const auto& f : frames) ms.push_back(1000.0 * StageSeconds(f)[s]);
    out[kStages[s]] = Stats(ms);
  }
  out["total"] = Stats(total);
  nlohmann::json per_frame = nlohmann::json::array();
  for (const auto& f : frames) {
    nlohmann::json row = nlohmann::json::array();
    for (const double seconds : StageSeconds(f)) row.push_back(std::round(1e4 * seconds) / 10.0);  // 0.1 ms
    per_frame.push_back(row);
  }
  out["frames_ms"] = per_frame;
  return out;
}

std::vector<LocalizationTimings> LocalizationTimesFromJson(const nlohmann::json& stats) {
  std::vector<LocalizationTimings> frames;
  if (!stats.contains("frames_ms")) return frames;
  for (const auto& row : stats["frames_ms"]) {
    if (row.size() != 4) continue;
    frames.push_back({row[0].get<double>() / 1000, row[1].get<double>() / 1000, row[2].get<double>() / 1000,
                      row[3].get<double>() / 1000});
  }
  return frames;
}

void WriteLocalizationTimeHistogram(const std::string& path, const std::string& title,
                                    const std::vector<LocalizationTimings>& frames) {
  constexpr int kWidth = 900, kHeight = 520;
  const cv::Rect plot(80, 60, 580, 380);
  cv::Mat image(kHeight, kWidth, CV_8UC3, kWhite);
  const cv::Scalar grid(225, 225, 225), axis(60, 60, 60);
  PutText(image, title, {16, 32}, 0.6, kInk, 2);
  double longest = 0.0;
  for (const auto& f : frames) longest = std::max(longest, 1000.0 * TotalSeconds(f));
  const double bin = NiceStep(std::max(longest, 10.0), 30);
  const int bins = std::max(1, static_cast<int>(std::ceil(std::max(longest, 10.0) / bin)) + 1);
  std::vector<std::array<double, 4>> stage_sum(static_cast<std::size_t>(bins), {0, 0, 0, 0});
  std::vector<int> count(static_cast<std::size_t>(bins), 0);
  for (const auto& f : frames) {
    const auto b = static_cast<std::size_t>(std::min(bins - 1, static_cast<int>(1000.0 * TotalSeconds(f) / bin)));
    ++count[b];
    for (std::size_t s = 0; s < 4; ++s) stage_sum[b][s] += StageSeconds(f)[s];
  }
  const int most = std::max(1, *std::max_element(count.begin(), count.end()));
  const double count_step = NiceStep(most, 5);
  const double count_top = std::ceil(most / count_step) * count_step;
  const auto y_of = [&](double c) {
    return plot.y + plot.height - static_cast<int>(std::lround(c / count_top * plot.height));
  };
  const auto x_of = [&](double ms) { return plot.x + static_cast<int>(std::lround(ms / (bins * bin) * plot.width)); };
  for (double c = 0; c <= count_top + 1e-9; c += count_step) {
    cv::line(image, {plot.x, y_of(c)}, {plot.x + plot.width, y_of(c)}, grid, 1);
    const std::string label = FormatNumber(c);
    PutText(image, label, {plot.x - 10 - TextSize(label, 0.42, 1).width, y_of(c) + 5}, 0.42, axis);
  }
  std::array<cv::Scalar, 4> colours;
  for (std::size_t s = 0; s < 4; ++s) colours[s] = HsvToRgb(40.0 + 80.0 * s, 0.7, 0.85);
  for (int b = 0; b < bins; ++b) {
    const auto i = static_cast<std::size_t>(b);
    if (count[i] == 0) continue;
    const double sum = stage_sum[i][0] + stage_sum[i][1] + stage_sum[i][2] + stage_sum[i][3];
    double below = 0.0;  // frames stacked so far, split by the stages' shares of this bin's time
    for (std::size_t s = 0; s < 4; ++s) {
      const double part = sum > 0 ? count[i] * stage_sum[i][s] / sum : 0.0;
      cv::rectangle(image, cv::Point(x_of(b * bin) + 1, y_of(below + part)),
                    cv::Point(x_of((b + 1) * bin) - 1, y_of(below)), colours[s], cv::FILLED);
      below += part;
    }
  }
  cv::rectangle(image, plot, axis, 1);
  const double tick = NiceStep(bins * bin, 8);
  for (double ms = 0; ms <= bins * bin + 1e-9; ms += tick) {
    PutTextCentred(image, FormatNumber(ms), {x_of(ms), plot.y + plot.height + 18}, 0.42, axis);
  }
  PutTextCentred(image, "processing time per ring frame (ms)", {plot.x + plot.width / 2, plot.y + plot.height + 44},
                 0.5, kInk);
  PutText(image, "frames", {10, plot.y - 12}, 0.45, kInk);
  const nlohmann::json stats = LocalizationTimeStats(frames);
  for (std::size_t s = 0; s < 4; ++s) {
    const int ly = plot.y + 14 + 24 * static_cast<int>(s);
    cv::rectangle(image, cv::Rect(plot.x + plot.width + 20, ly - 11, 14, 14), colours[s], cv::FILLED);
    PutText(
        image,
        std::string(kStages[s]) + "  median " + FormatFixed(stats[kStages[s]]["median_ms"].get<double>(), 1) + " ms",
        {plot.x + plot.width + 40, ly}, 0.42, kInk);
  }
  const int ty = plot.y + 14 + 24 * 5;
  PutText(image, "total  median " + FormatFixed(stats["total"]["median_ms"].get<double>(), 1) + " ms",
          {plot.x + plot.width + 20, ty}, 0.45, kInk, 1);
  PutText(image,
          "p90 " + FormatFixed(stats["total"]["p90_ms"].get<double>(), 1) + " ms, " + std::to_string(frames.size()) +
              " frames",
          {plot.x + plot.width + 20, ty + 22}, 0.42, axis);
  PutText(image, "bars split by each stage's share of the time in the bin", {plot.x, kHeight - 14}, 0.4, axis);
  WritePng(path, image);
}

}  // namespace trimbot::scenarios
