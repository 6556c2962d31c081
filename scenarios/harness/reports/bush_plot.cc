#include "reports/bush_plot.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reports/drawing.h"
#include "reports/output_files.h"

namespace trimbot::scenarios {
namespace {

constexpr double kReferenceDistanceCm = 1.26;  // D3.4 Figure 20: mean over 5 trials
constexpr double kReferenceBearingDeg = 2.08;

const cv::Scalar kTruth(120, 120, 120), kEstimate(40, 110, 200), kReached(220, 120, 40), kReference(200, 40, 40);

}  // namespace

void WriteBushFramePlot(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials) {
  const auto trial =
      std::find_if(trials.begin(), trials.end(), [](const TrialResult& t) { return !t.bush_frames.empty(); });
  if (trial == trials.end()) return;
  std::vector<int> goals;
  for (const BushFrame& f : trial->bush_frames) {
    if (std::find(goals.begin(), goals.end(), f.goal) == goals.end() && goals.size() < 5) goals.push_back(f.goal);
  }
  const int row_height = 170, width = 1100;
  cv::Mat image(90 + row_height * static_cast<int>(goals.size()), width, CV_8UC3, kWhite);
  PutText(image, title + " (trial " + std::to_string(trial->index) + ")", {16, 30}, 0.6, kInk, 2);
  Legend(image, 58, {{"ground truth", kTruth}, {"stack's estimate per frame", kEstimate}});
  for (std::size_t row = 0; row < goals.size(); ++row) {
    std::vector<cv::Point2d> true_distance, estimated_distance, true_bearing, estimated_bearing;
    for (const BushFrame& f : trial->bush_frames) {
      if (f.goal != goals[row]) continue;
      true_distance.emplace_back(f.t, f.true_distance_m);
      true_bearing.emplace_back(f.t, f.true_bearing_deg);
      if (!f.found) continue;
      estimated_distance.emplace_back(f.t, f.true_distance_m + f.distance_error_m);
      estimated_bearing.emplace_back(f.t, f.true_bearing_deg + f.bearing_error_deg);
    }
    const int top = 90 + row_height * static_cast<int>(row) + 12;
    const std::string goal = "goal " + std::to_string(goals[row]);
    double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
    Extent(true_distance, &x0, &x1, &y0, &y1);
    Extent(estimated_distance, &x0, &x1, &y0, &y1);
    Panel distance(image, {80, top, 420, row_height - 40}, x0, x1, y0, y1,
                   goal + ": distance to the bush's centre (m) over time");
    distance.Line(true_distance, kTruth, 2);
    distance.Dots(estimated_distance, kEstimate);
    y0 = std::numeric_limits<double>::infinity(), y1 = -y0;
    Extent(true_bearing, &x0, &x1, &y0, &y1);
    Extent(estimated_bearing, &x0, &x1, &y0, &y1);
    Panel bearing(image, {620, top, 420, row_height - 40}, x0, x1, y0, y1,
                  goal + ": bearing of the bush (deg) over time");
    bearing.Line(true_bearing, kTruth, 2);
    bearing.Dots(estimated_bearing, kEstimate);
  }
  WritePng(path, image);
}

void WriteBushErrorPlot(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials) {
  // One column per bush goal of each trial: the mean per-frame error at 1-3 m, and at arrival the
  // estimate's error and the reached pose's error from the target.
  struct Column {
    std::string label;
    double frame_distance_cm = 0, frame_bearing_deg = 0, estimate_distance_cm = 0, estimate_bearing_deg = 0,
           reached_distance_cm = 0, reached_bearing_deg = 0;
  };
  std::vector<Column> columns;
  for (const TrialResult& trial : trials) {
    for (std::size_t g = 0; g < trial.goals.size(); ++g) {
      const GoalResult& goal = trial.goals[g];
      if (goal.bush == 0 || goal.arrival_time < 0.0) continue;
      Column c;
      c.label = std::to_string(goal.bush);
      int n = 0;
      for (const BushFrame& f : trial.bush_frames) {
        if (f.goal != static_cast<int>(g) || !f.found || f.true_distance_m < 1.0 || f.true_distance_m > 3.0) continue;
        c.frame_distance_cm += 100.0 * std::abs(f.distance_error_m);
        c.frame_bearing_deg += std::abs(f.bearing_error_deg);
        ++n;
      }
      if (n > 0) c.frame_distance_cm /= n, c.frame_bearing_deg /= n;
      c.estimate_distance_cm = 100.0 * std::abs(goal.bush_estimate_distance_error_m);
      c.estimate_bearing_deg = std::abs(goal.bush_estimate_bearing_error_deg);
      c.reached_distance_cm = 100.0 * std::abs(goal.bush_distance_error_m);
      c.reached_bearing_deg = std::abs(goal.bush_bearing_error_deg);
      columns.push_back(c);
    }
  }
  if (columns.empty()) return;
  const int width = std::max(900, 120 + 30 * static_cast<int>(columns.size()));
  cv::Mat image(640, width, CV_8UC3, kWhite);
  PutText(image, title, {16, 30}, 0.6, kInk, 2);
  Legend(image, 58,
         {{"per frame at 1-3 m (mean)", kTruth},
          {"estimate at arrival", kEstimate},
          {"pose reached vs target", kReached},
          {"real robot (D3.4 Fig. 20)", kReference}});
  const double n = static_cast<double>(columns.size());
  const auto draw = [&](int top, const std::string& label, double reference, auto frame, auto estimate, auto reached) {
    double high = reference;
    for (const Column& c : columns) high = std::max({high, frame(c), estimate(c), reached(c)});
    Panel panel(image, {80, top, width - 120, 220}, 0.0, n, 0.0, high, label);
    panel.Horizontal(reference, kReference);
    for (std::size_t i = 0; i < columns.size(); ++i) {
      const double x = static_cast<double>(i);
      const auto bar = [&](double offset, double value, const cv::Scalar& colour) {
        cv::rectangle(image, panel.At(x + offset, 0.0), panel.At(x + offset + 0.25, value), colour, cv::FILLED);
      };
      bar(0.12, frame(columns[i]), kTruth);
      bar(0.37, estimate(columns[i]), kEstimate);
      bar(0.62, reached(columns[i]), kReached);
      if (columns.size() <= 64)
        PutTextCentred(image, columns[i].label, panel.At(x + 0.5, 0.0) + cv::Point(0, 14), 0.3, kAxis);
    }
  };
  draw(
      100, "distance error (cm), by bush id", kReferenceDistanceCm, [](const Column& c) { return c.frame_distance_cm; },
      [](const Column& c) { return c.estimate_distance_cm; }, [](const Column& c) { return c.reached_distance_cm; });
  draw(
      380, "bearing error (deg), by bush id", kReferenceBearingDeg, [](const Column& c) { return c.frame_bearing_deg; },
      [](const Column& c) { return c.estimate_bearing_deg; }, [](const Column& c) { return c.reached_bearing_deg; });
  WritePng(path, image);
}

}  // namespace trimbot::scenarios
