#include "reports/sweep_plot.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reports/drawing.h"
#include "reports/output_files.h"

namespace trimbot::scenarios {
namespace {

constexpr int kWidth = 900, kHeight = 560;
const cv::Rect kPlot(90, 60, 560, 400);  // legend to the right

// y range over all finite values and interval ends, padded, with a nice step.
void YRange(const std::vector<SweepSeries>& series, double* low, double* high, double* step) {
  *low = std::numeric_limits<double>::infinity();
  *high = -*low;
  for (const auto& s : series) {
    for (std::size_t i = 0; i < s.value.size(); ++i) {
      for (double v : {s.value[i], s.low[i], s.high[i]}) {
        if (std::isfinite(v)) *low = std::min(*low, v), *high = std::max(*high, v);
      }
    }
  }
  if (!std::isfinite(*low)) *low = 0.0, *high = 1.0;
  if (*high - *low < 1e-12)
    *low -= 0.5 * std::max(1e-3, std::abs(*low)), *high += 0.5 * std::max(1e-3, std::abs(*high));
  *step = NiceStep(*high - *low, 6);
  *low = std::floor(*low / *step) * *step;
  *high = std::ceil(*high / *step) * *step;
}

}  // namespace

void WriteSweepPlot(const std::string& path, const std::string& title, const std::string& x_label,
                    const std::vector<std::string>& x_values, const std::string& y_label,
                    const std::vector<SweepSeries>& series) {
  cv::Mat image(kHeight, kWidth, CV_8UC3, kWhite);
  double y_low = 0, y_high = 1, y_step = 1;
  YRange(series, &y_low, &y_high, &y_step);
  const auto y_of = [&](double v) {
    return kPlot.y + kPlot.height - static_cast<int>(std::lround((v - y_low) / (y_high - y_low) * kPlot.height));
  };
  const int n = static_cast<int>(x_values.size());
  const auto x_of = [&](int i) {
    return kPlot.x + static_cast<int>(std::lround((i + 0.5) * kPlot.width / std::max(1, n)));
  };
  const cv::Scalar grid(225, 225, 225), axis(60, 60, 60);
  PutText(image, title, {16, 32}, 0.65, kInk, 2);
  for (double v = y_low; v <= y_high + 1e-9 * y_step; v += y_step) {
    cv::line(image, {kPlot.x, y_of(v)}, {kPlot.x + kPlot.width, y_of(v)}, grid, 1);
    const std::string label = FormatNumber(v);
    PutText(image, label, {kPlot.x - 10 - TextSize(label, 0.42, 1).width, y_of(v) + 5}, 0.42, axis);
  }
  cv::rectangle(image, kPlot, axis, 1);
  for (int i = 0; i < n; ++i) PutTextCentred(image, x_values[i], {x_of(i), kPlot.y + kPlot.height + 18}, 0.45, axis);
  PutTextCentred(image, x_label, {kPlot.x + kPlot.width / 2, kPlot.y + kPlot.height + 48}, 0.5, kInk);
  PutText(image, y_label, {10, kPlot.y - 12}, 0.45, kInk);
  for (std::size_t k = 0; k < series.size(); ++k) {
    const SweepSeries& s = series[k];
    const cv::Scalar colour = HsvToRgb(360.0 * k / std::max<std::size_t>(1, series.size()) + 210.0, 0.75, 0.8);
    const int offset = static_cast<int>(k) * 6 - static_cast<int>(series.size()) * 3;  // keep bars apart
    cv::Point previous(-1, -1);
    for (int i = 0; i < n && i < static_cast<int>(s.value.size()); ++i) {
      if (!std::isfinite(s.value[i])) continue;
      const cv::Point p(x_of(i) + offset, y_of(s.value[i]));
      cv::line(image, {p.x, y_of(s.low[i])}, {p.x, y_of(s.high[i])}, colour, 2, cv::LINE_AA);
      for (double end : {s.low[i], s.high[i]}) cv::line(image, {p.x - 5, y_of(end)}, {p.x + 5, y_of(end)}, colour, 2);
      if (previous.x >= 0) cv::line(image, previous, p, colour, 1, cv::LINE_AA);
      cv::circle(image, p, 5, colour, cv::FILLED, cv::LINE_AA);
      previous = p;
    }
    const int ly = kPlot.y + 14 + 22 * static_cast<int>(k);
    cv::circle(image, {kPlot.x + kPlot.width + 24, ly - 5}, 5, colour, cv::FILLED, cv::LINE_AA);
    PutText(image, s.label.empty() ? "all points" : s.label, {kPlot.x + kPlot.width + 36, ly}, 0.4, kInk);
  }
  PutText(image, "error bars: 95 % intervals (Wilson for rates, bootstrap over trials for means)",
          {kPlot.x, kHeight - 14}, 0.4, axis);
  WritePng(path, image);
}

}  // namespace trimbot::scenarios
