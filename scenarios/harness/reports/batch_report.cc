#include "reports/batch_report.h"

#include "evaluation/tum_trajectory.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

#include "reports/drawing.h"
#include "reports/output_files.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {

std::string XmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      // Line breaks survive in attributes only as character references.
      case '\n':
        out += "&#10;";
        break;
      case '\r':
        out += "&#13;";
        break;
      case '\t':
        out += "&#9;";
        break;
      default:
        // Other control characters are not allowed anywhere in XML 1.0.
        out += static_cast<unsigned char>(ch) < 0x20 ? '?' : ch;
    }
  }
  return out;
}

namespace {

// ---- JUnit XML --------------------------------------------------------------------------------

std::string FormatSeconds(double seconds) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3) << seconds;
  return out.str();
}

std::string TrialTestName(const TrialResult& trial) {
  char index[16];
  std::snprintf(index, sizeof(index), "%03d", trial.index);
  return std::string("trial ") + index + " seed " + std::to_string(trial.seed);
}

// ---- trajectory plot --------------------------------------------------------------------------

constexpr int kPlotWidth = 1200;
constexpr int kTitleBandHeight = 48;
constexpr int kLegendMargin = 16;
constexpr int kLegendRowHeight = 26;
constexpr int kLegendEntryWidth = 190;

// Map frame (metres, y up) -> image pixels (y down, row 0 = the map's largest y).
struct MapToImage {
  Eigen::Vector2d origin;
  double map_height_m = 0.0;
  double pixels_per_metre = 1.0;
  cv::Point2d offset;  // image pixel of the map's top-left corner

  cv::Point2d operator()(const Eigen::Vector2d& p) const {
    return {offset.x + (p.x() - origin.x()) * pixels_per_metre,
            offset.y + (map_height_m - (p.y() - origin.y())) * pixels_per_metre};
  }
};

struct TrialColours {
  cv::Scalar ground_truth, estimate;
};

// Successful trials take hues spread by the golden angle, kept clear of red; failed trials are
// shades of red so they stand out.
TrialColours ColoursFor(int position, int failed_position, bool success) {
  if (success) {
    const double hue = 25.0 + std::fmod(175.0 + position * 137.508, 305.0);  // 25..330 degrees
    return {HsvToRgb(hue, 0.85, 0.8), HsvToRgb(hue, 1.0, 0.45)};
  }
  const double hue = 355.0 + 8.0 * (failed_position % 3);
  const double value = 0.9 - 0.15 * ((failed_position / 3) % 3);
  return {HsvToRgb(hue, 0.9, value), HsvToRgb(hue, 1.0, value * 0.5)};
}

// A path as polylines, broken where a point is not finite.
void DrawPath(cv::Mat& image, const std::vector<Eigen::Vector2d>& path, const MapToImage& to_image,
              const cv::Scalar& colour, int thickness) {
  std::vector<cv::Point> run;
  const auto flush = [&] {
    if (run.size() == 1) {
      cv::circle(image, run.front(), std::max(1, thickness / 2) << kSubpixelBits, colour, cv::FILLED, cv::LINE_AA,
                 kSubpixelBits);
    } else if (run.size() > 1) {
      cv::polylines(image, run, false, colour, thickness, cv::LINE_AA, kSubpixelBits);
    }
    run.clear();
  };
  for (const Eigen::Vector2d& p : path) {
    if (p.allFinite()) {
      run.push_back(FixedPoint(to_image(p)));
    } else {
      flush();
    }
  }
  flush();
}

void DrawGoal(cv::Mat& image, cv::Point centre, int number) {
  constexpr int kRadius = 13;
  cv::circle(image, centre, kRadius, kWhite, cv::FILLED, cv::LINE_AA);
  cv::circle(image, centre, kRadius, kInk, 2, cv::LINE_AA);
  PutTextCentred(image, std::to_string(number), centre, number < 10 ? 0.5 : 0.4, kInk, 1);
}

Eigen::Vector2d MapSize(const garden::OccupancyMap& map) {
  return {map.occupied.cols * map.resolution, map.occupied.rows * map.resolution};
}

const cv::Scalar kNotInMap(215, 140, 70);  // orange (RGB, as every colour here): in the true_map, not in the map

cv::Mat RenderMap(const garden::OccupancyMap& map, const garden::OccupancyMap& true_map, cv::Size size_px,
                  const MapToImage& to_image) {
  const cv::Scalar kFree(248, 248, 244), kOccupied(90, 90, 90), kGridLine(222, 222, 218);
  cv::Mat occupied, in_garden;
  cv::resize(map.occupied, occupied, size_px, 0, 0, cv::INTER_NEAREST);
  cv::resize(true_map.occupied, in_garden, size_px, 0, 0, cv::INTER_NEAREST);
  cv::Mat image(size_px, CV_8UC3, kFree);
  // 1 m grid, on free space only, to read distances anywhere on the map.
  const Eigen::Vector2d low = map.origin, high = map.origin + MapSize(map);
  const cv::Point2d shift(-to_image.offset.x, -to_image.offset.y);  // this image starts at the map corner
  for (double x = std::ceil(low.x()); x <= high.x(); x += 1.0) {
    cv::line(image, FixedPoint(to_image({x, low.y()}) + shift), FixedPoint(to_image({x, high.y()}) + shift), kGridLine,
             1, cv::LINE_8, kSubpixelBits);
  }
  for (double y = std::ceil(low.y()); y <= high.y(); y += 1.0) {
    cv::line(image, FixedPoint(to_image({low.x(), y}) + shift), FixedPoint(to_image({high.x(), y}) + shift), kGridLine,
             1, cv::LINE_8, kSubpixelBits);
  }
  image.setTo(kNotInMap, in_garden & ~occupied);
  image.setTo(kOccupied, occupied);
  return image;
}

bool MapLacksSomething(const garden::OccupancyMap& map, const garden::OccupancyMap& true_map) {
  return cv::countNonZero(true_map.occupied & ~map.occupied) > 0;
}

int LegendHeight(std::size_t trajectories) {
  const int per_row = std::max(1, (kPlotWidth - 2 * kLegendMargin) / kLegendEntryWidth);
  const int trial_rows = static_cast<int>((trajectories + per_row - 1) / per_row);
  return kLegendMargin + kLegendRowHeight * (1 + trial_rows) + kLegendMargin / 2;
}

void DrawLegend(cv::Mat& image, int top, const std::vector<PlotTrajectory>& trajectories,
                const std::vector<TrialColours>& colours, double pixels_per_metre, bool not_in_map) {
  const cv::Scalar kKeyGrey(110, 110, 110);
  int y = top + kLegendMargin + kLegendRowHeight / 2;
  int x = kLegendMargin;
  // Scale bar: 1 m with end ticks.
  const int bar = static_cast<int>(std::lround(pixels_per_metre));
  cv::line(image, {x, y}, {x + bar, y}, kInk, 2);
  cv::line(image, {x, y - 6}, {x, y + 6}, kInk, 2);
  cv::line(image, {x + bar, y - 6}, {x + bar, y + 6}, kInk, 2);
  PutText(image, "1 m", {x + bar + 8, y + 6}, 0.55, kInk);
  x += bar + 70;
  // Key to the line styles and markers.
  cv::line(image, {x, y}, {x + 36, y}, kKeyGrey, 3, cv::LINE_AA);
  PutText(image, "ground truth", {x + 44, y + 6}, 0.5, kInk);
  x += 44 + TextSize("ground truth", 0.5, 1).width + 24;
  cv::line(image, {x, y}, {x + 36, y}, kKeyGrey, 1, cv::LINE_AA);
  PutText(image, "EKF estimate", {x + 44, y + 6}, 0.5, kInk);
  x += 44 + TextSize("EKF estimate", 0.5, 1).width + 24;
  cv::circle(image, {x + 6, y}, 5, kKeyGrey, cv::FILLED, cv::LINE_AA);
  PutText(image, "start", {x + 18, y + 6}, 0.5, kInk);
  x += 18 + TextSize("start", 0.5, 1).width + 24;
  DrawGoal(image, {x + 13, y}, 1);
  PutText(image, "goals, in order", {x + 34, y + 6}, 0.5, kInk);
  x += 34 + TextSize("goals, in order", 0.5, 1).width + 24;
  if (not_in_map) {
    cv::rectangle(image, {x, y - 6}, {x + 14, y + 6}, kNotInMap, cv::FILLED);
    PutText(image, "in the garden, not in the robot's map", {x + 22, y + 6}, 0.5, kInk);
  }

  const int per_row = std::max(1, (kPlotWidth - 2 * kLegendMargin) / kLegendEntryWidth);
  for (std::size_t i = 0; i < trajectories.size(); ++i) {
    const int row = static_cast<int>(i) / per_row + 1, column = static_cast<int>(i) % per_row;
    const cv::Point at(kLegendMargin + column * kLegendEntryWidth, y + row * kLegendRowHeight);
    cv::line(image, {at.x, at.y - 3}, {at.x + 36, at.y - 3}, colours[i].ground_truth, 3, cv::LINE_AA);
    cv::line(image, {at.x, at.y + 4}, {at.x + 36, at.y + 4}, colours[i].estimate, 1, cv::LINE_AA);
    const std::string label =
        "trial " + std::to_string(trajectories[i].trial) + (trajectories[i].success ? "" : " (failed)");
    PutText(image, label, {at.x + 44, at.y + 6}, 0.5, trajectories[i].success ? kInk : cv::Scalar(190, 20, 20));
  }
}

// ---- histograms -------------------------------------------------------------------------------

constexpr int kPanelWidth = 600, kPanelHeight = 420;
constexpr double kBinCm = 2.0, kMinRangeCm = 50.0;

// `phase` shifts the dashes, so that two lines at the same place stay visible in turn.
void DrawDashedVertical(cv::Mat& image, int x, int top, int bottom, const cv::Scalar& colour, int thickness,
                        int phase) {
  for (int y = top + phase; y < bottom; y += 10)
    cv::line(image, {x, y}, {x, std::min(y + 4, bottom)}, colour, thickness);
}

struct Histogram {
  double range_cm = 0.0;
  std::vector<int> counts;  // per bin of kBinCm
  int beyond = 0;           // samples above the range
};

// Bins of 2 cm up to the 99th percentile (at least 50 cm), so that rare outliers do not squash
// the bulk of the distribution; what lies beyond is counted.
Histogram BinCentimetres(const std::vector<double>& samples_m) {
  std::vector<double> samples_cm(samples_m.size());
  std::transform(samples_m.begin(), samples_m.end(), samples_cm.begin(), [](double m) { return m * 100.0; });
  std::sort(samples_cm.begin(), samples_cm.end());
  Histogram h;
  h.range_cm = kMinRangeCm;
  if (!samples_cm.empty()) {
    const double p99 = samples_cm[static_cast<std::size_t>(std::floor(0.99 * (samples_cm.size() - 1)))];
    h.range_cm = std::max(kMinRangeCm, std::ceil(p99 / kBinCm) * kBinCm);
  }
  const int bins = static_cast<int>(std::lround(h.range_cm / kBinCm));
  h.counts.assign(bins, 0);
  for (const double s : samples_cm) {
    if (s > h.range_cm) {
      ++h.beyond;
    } else {
      ++h.counts[std::clamp(static_cast<int>(s / kBinCm), 0, bins - 1)];
    }
  }
  return h;
}

void DrawHistogramPanel(cv::Mat& image, cv::Rect panel, const std::string& name, std::vector<double> samples_m) {
  const cv::Scalar kBar(86, 135, 190), kBarEdge(40, 75, 120), kMean(200, 40, 40), kMedian(230, 140, 20),
      kGridLine(232, 232, 232);
  samples_m.erase(std::remove_if(samples_m.begin(), samples_m.end(), [](double s) { return !std::isfinite(s); }),
                  samples_m.end());
  const ErrorStats stats = ErrorStats::From(samples_m);
  const Histogram histogram = BinCentimetres(samples_m);
  const double range_cm = histogram.range_cm;
  const std::vector<int>& counts = histogram.counts;
  const int bins = static_cast<int>(counts.size());
  const int beyond = histogram.beyond;
  const int max_count = std::max(1, *std::max_element(counts.begin(), counts.end()));
  const double y_step = std::max(1.0, NiceStep(max_count, 5));
  const double y_top = std::ceil(max_count / y_step) * y_step;

  // Plot area inside the panel: room for the title above and the tick labels left and below.
  const cv::Rect plot(panel.x + 70, panel.y + 84, panel.width - 70 - 24, panel.height - 84 - 56);
  const auto x_of = [&](double cm) { return plot.x + static_cast<int>(std::lround(cm / range_cm * plot.width)); };
  const auto y_of = [&](double count) {
    return plot.y + plot.height - static_cast<int>(std::lround(count / y_top * plot.height));
  };

  const std::string heading = name + ": mean " + FormatFixed(stats.mean * 100.0, 1) + " cm, median " +
                              FormatFixed(stats.median * 100.0, 1) + " cm";
  PutText(image, heading, {panel.x + 16, panel.y + 28}, 0.62, kInk, 2);
  std::string subtitle = "n = " + std::to_string(stats.count) + " samples, bins of 2 cm";
  if (beyond > 0) {
    subtitle += "; " + std::to_string(beyond) + " above " + FormatNumber(range_cm) + " cm (max " +
                FormatFixed(stats.max * 100.0, 1) + " cm)";
  }
  PutText(image, subtitle, {panel.x + 16, panel.y + 50}, 0.45, kAxis);

  // Horizontal grid lines and count ticks.
  for (double c = 0.0; c <= y_top + 1e-9; c += y_step) {
    const int y = y_of(c);
    if (c > 0) cv::line(image, {plot.x, y}, {plot.x + plot.width, y}, kGridLine, 1);
    cv::line(image, {plot.x - 5, y}, {plot.x, y}, kAxis, 1);
    const std::string label = FormatNumber(c);
    PutText(image, label, {plot.x - 9 - TextSize(label, 0.42, 1).width, y + 5}, 0.42, kAxis);
  }
  // Bars.
  for (int b = 0; b < bins; ++b) {
    if (counts[b] == 0) continue;
    const cv::Rect bar(cv::Point(x_of(b * kBinCm), y_of(counts[b])), cv::Point(x_of((b + 1) * kBinCm), y_of(0)));
    cv::rectangle(image, bar, kBar, cv::FILLED);
    if (bar.width >= 6) cv::rectangle(image, bar, kBarEdge, 1);  // narrower bars would be all edge
  }
  // Axes, x ticks in cm.
  cv::line(image, {plot.x, plot.y}, {plot.x, plot.y + plot.height}, kAxis, 1);
  cv::line(image, {plot.x, plot.y + plot.height}, {plot.x + plot.width, plot.y + plot.height}, kAxis, 1);
  const double x_step = NiceStep(range_cm, 8);
  for (double cm = 0.0; cm <= range_cm + 1e-9; cm += x_step) {
    const int x = x_of(cm);
    cv::line(image, {x, plot.y + plot.height}, {x, plot.y + plot.height + 5}, kAxis, 1);
    PutTextCentred(image, FormatNumber(cm), {x, plot.y + plot.height + 16}, 0.42, kAxis);
  }
  PutTextCentred(image, "position error (cm)", {plot.x + plot.width / 2, plot.y + plot.height + 42}, 0.5, kInk);
  PutText(image, "samples", {panel.x + 8, plot.y - 12}, 0.42, kAxis);

  if (stats.count == 0) {
    PutTextCentred(image, "no samples", {plot.x + plot.width / 2, plot.y + plot.height / 2}, 0.7, kAxis, 1);
    return;
  }
  // Mean and median markers, with a key in the top-right corner.
  const int x_mean = x_of(std::min(stats.mean * 100.0, range_cm));
  const int x_median = x_of(std::min(stats.median * 100.0, range_cm));
  DrawDashedVertical(image, x_median, plot.y, plot.y + plot.height, kMedian, 2, 0);
  DrawDashedVertical(image, x_mean, plot.y, plot.y + plot.height, kMean, 2, 5);
  const int key_x = plot.x + plot.width - 110;
  cv::rectangle(image, cv::Rect(key_x - 8, plot.y + 2, 110, 44), kWhite, cv::FILLED);
  cv::rectangle(image, cv::Rect(key_x - 8, plot.y + 2, 110, 44), kGridLine, 1);
  cv::line(image, {key_x, plot.y + 12}, {key_x + 24, plot.y + 12}, kMean, 2);
  PutText(image, "mean", {key_x + 30, plot.y + 17}, 0.45, kInk);
  cv::line(image, {key_x, plot.y + 32}, {key_x + 24, plot.y + 32}, kMedian, 2);
  PutText(image, "median", {key_x + 30, plot.y + 37}, 0.45, kInk);
}

// The robot's map (and what the garden has that it lacks) in an image about kPlotWidth wide, under
// a title band, with `legend_height` pixels left below it.
struct MapCanvas {
  cv::Mat image;
  MapToImage to_image;
  int legend_top = 0;
};
MapCanvas DrawMapCanvas(const std::string& path, const garden::OccupancyMap& map, const garden::OccupancyMap& true_map,
                        int legend_height, const std::string& title) {
  const Eigen::Vector2d map_size = MapSize(map);
  if (map.occupied.empty() || map_size.x() <= 0 || map_size.y() <= 0) {
    throw std::invalid_argument(path + ": cannot plot over an empty map");
  }
  if (true_map.occupied.size() != map.occupied.size()) {
    throw std::invalid_argument(path + ": the true_map's map must have the prior map's cells");
  }
  // About 1200 px wide; a very tall map is scaled to keep the image a sensible height instead.
  MapCanvas canvas;
  MapToImage& to_image = canvas.to_image;
  to_image.origin = map.origin;
  to_image.map_height_m = map_size.y();
  to_image.pixels_per_metre = std::min(kPlotWidth / map_size.x(), 2.0 * kPlotWidth / map_size.y());
  const cv::Size map_px(static_cast<int>(std::lround(map_size.x() * to_image.pixels_per_metre)),
                        static_cast<int>(std::lround(map_size.y() * to_image.pixels_per_metre)));
  to_image.offset = {static_cast<double>((kPlotWidth - map_px.width) / 2), static_cast<double>(kTitleBandHeight)};
  canvas.legend_top = kTitleBandHeight + map_px.height;
  canvas.image = cv::Mat(canvas.legend_top + legend_height, kPlotWidth, CV_8UC3, kWhite);
  const cv::Rect map_area(cv::Point(static_cast<int>(to_image.offset.x), kTitleBandHeight), map_px);
  RenderMap(map, true_map, map_px, to_image).copyTo(canvas.image(map_area));
  cv::rectangle(canvas.image, map_area, cv::Scalar(150, 150, 150), 1);
  PutText(canvas.image, title, {kLegendMargin, 32}, 0.8, kInk, 2);
  return canvas;
}

// A frame's outcome (localization.csv) as one of the plot's classes, and the class's colour.
struct OutcomeClass {
  std::string label;
  cv::Scalar colour;
};
const std::vector<OutcomeClass>& OutcomeClasses() {
  static const std::vector<OutcomeClass> classes = {{"fix accepted", cv::Scalar(40, 160, 60)},
                                                    {"no pose", cv::Scalar(240, 150, 20)},
                                                    {"fix rejected by the EKF", cv::Scalar(200, 20, 20)},
                                                    {"relocalized", cv::Scalar(120, 40, 200)},
                                                    {"other (too old, pending)", cv::Scalar(130, 130, 130)}};
  return classes;
}
std::size_t OutcomeClassOf(const std::string& outcome) {
  if (outcome == "accepted") return 0;
  if (outcome.rfind("no pose", 0) == 0) return 1;
  if (outcome == "rejected as an outlier") return 2;
  if (outcome == "relocalized") return 3;
  return 4;
}

}  // namespace

void WriteJunitXml(const std::string& path, const BatchSummary& summary) {
  int failures = 0;
  double wall_seconds = 0.0;
  for (const CriterionResult& criterion : summary.criteria) failures += criterion.pass ? 0 : 1;
  for (const TrialResult& trial : summary.trials) {
    failures += trial.success ? 0 : 1;
    wall_seconds += trial.wall_seconds;
  }
  const std::size_t tests = summary.criteria.size() + summary.trials.size();
  const std::string scenario = XmlEscape(summary.scenario);
  const std::string counts = "tests=\"" + std::to_string(tests) + "\" failures=\"" + std::to_string(failures) +
                             "\" errors=\"0\" time=\"" + FormatSeconds(wall_seconds) + "\"";

  std::ostringstream xml;
  xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml << "<testsuites name=\"" << scenario << "\" " << counts << ">\n";
  xml << "  <testsuite name=\"" << scenario << "\" " << counts << ">\n";
  xml << "    <properties>\n"
      << "      <property name=\"scenario_file\" value=\"" << XmlEscape(summary.scenario_file) << "\"/>\n"
      << "      <property name=\"seed\" value=\"" << summary.seed << "\"/>\n"
      << "      <property name=\"trials_planned\" value=\"" << summary.trials_planned << "\"/>\n"
      << "    </properties>\n";
  for (const CriterionResult& criterion : summary.criteria) {
    xml << "    <testcase classname=\"" << scenario << ".criteria\" name=\""
        << XmlEscape(criterion.name + " " + criterion.comparison + " " + FormatNumber(criterion.expected))
        << "\" time=\"0\"";
    if (criterion.pass) {
      xml << "/>\n";
    } else {
      xml << ">\n      <failure message=\""
          << XmlEscape("expected " + criterion.name + " " + criterion.comparison + " " +
                       FormatNumber(criterion.expected) + ", actual " + FormatNumber(criterion.actual))
          << "\"/>\n    </testcase>\n";
    }
  }
  for (const TrialResult& trial : summary.trials) {
    xml << "    <testcase classname=\"" << scenario << ".trials\" name=\"" << XmlEscape(TrialTestName(trial))
        << "\" time=\"" << FormatSeconds(trial.wall_seconds) << "\"";
    if (trial.success) {
      xml << "/>\n";
      continue;
    }
    const std::string message = trial.message.empty() ? trial.status : trial.status + ": " + trial.message;
    xml << ">\n      <failure message=\"" << XmlEscape(message) << "\" type=\"" << XmlEscape(trial.status) << "\"";
    if (trial.faults.empty()) {
      xml << "/>\n";
    } else {
      // The injected faults help to tell a bug from a fault the robot was not expected to survive.
      std::string faults = "injected faults:";
      for (const std::string& fault : trial.faults) faults += "\n  " + fault;
      xml << ">" << XmlEscape(faults) << "</failure>\n";
    }
    xml << "    </testcase>\n";
  }
  xml << "  </testsuite>\n</testsuites>\n";
  WriteFileAtomically(path, xml.str());
}

void WriteTrajectoryPlot(const std::string& path, const garden::OccupancyMap& map, const garden::OccupancyMap& true_map,
                         const std::vector<PlotTrajectory>& trajectories, const std::vector<Eigen::Vector2d>& goals,
                         const std::string& title) {
  MapCanvas canvas = DrawMapCanvas(path, map, true_map, LegendHeight(trajectories.size()), title);
  cv::Mat& image = canvas.image;
  const MapToImage& to_image = canvas.to_image;
  const int legend_top = canvas.legend_top;

  std::vector<TrialColours> colours;
  int successes = 0, failures = 0;
  for (const PlotTrajectory& trajectory : trajectories) {
    colours.push_back(trajectory.success ? ColoursFor(successes++, 0, true) : ColoursFor(0, failures++, false));
  }
  // All ground truths first, so that no thick line hides an estimate.
  for (std::size_t i = 0; i < trajectories.size(); ++i) {
    DrawPath(image, trajectories[i].ground_truth, to_image, colours[i].ground_truth, 3);
  }
  for (std::size_t i = 0; i < trajectories.size(); ++i) {
    DrawPath(image, trajectories[i].estimate, to_image, colours[i].estimate, 1);
    const auto& truth = trajectories[i].ground_truth;
    const auto start = std::find_if(truth.begin(), truth.end(), [](const Eigen::Vector2d& p) { return p.allFinite(); });
    if (start != truth.end()) {
      cv::circle(image, FixedPoint(to_image(*start)), 5 << kSubpixelBits, colours[i].ground_truth, cv::FILLED,
                 cv::LINE_AA, kSubpixelBits);
      cv::circle(image, FixedPoint(to_image(*start)), 5 << kSubpixelBits, kInk, 1, cv::LINE_AA, kSubpixelBits);
    }
  }
  for (std::size_t g = 0; g < goals.size(); ++g) {
    if (!goals[g].allFinite()) continue;
    const cv::Point2d centre = to_image(goals[g]);
    DrawGoal(image, {static_cast<int>(std::lround(centre.x)), static_cast<int>(std::lround(centre.y))},
             static_cast<int>(g) + 1);
  }
  DrawLegend(image, legend_top, trajectories, colours, to_image.pixels_per_metre, MapLacksSomething(map, true_map));
  WritePng(path, image, true);
}

void WriteErrorHistograms(const std::string& path, const std::vector<TrialResult>& trials, const std::string& title) {
  std::vector<std::string> names;  // in order of first appearance
  std::map<std::string, std::vector<double>> pooled_m;
  for (const TrialResult& trial : trials) {
    for (const EstimateErrors& estimate : trial.estimates) {
      if (!pooled_m.count(estimate.name)) names.push_back(estimate.name);
      auto& pool = pooled_m[estimate.name];
      pool.insert(pool.end(), estimate.position_m.begin(), estimate.position_m.end());
    }
  }
  const int panels = std::max<int>(1, static_cast<int>(names.size()));
  const int columns = std::min(panels, 3), rows = (panels + columns - 1) / columns;
  constexpr int kTitleHeight = 50;
  cv::Mat image(kTitleHeight + rows * kPanelHeight, columns * kPanelWidth, CV_8UC3, kWhite);
  PutText(image, title, {16, 34}, 0.8, kInk, 2);
  if (names.empty()) {
    PutTextCentred(image, "no localization error samples", {image.cols / 2, kTitleHeight + kPanelHeight / 2}, 0.7,
                   kInk);
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    const cv::Rect panel(static_cast<int>(i % columns) * kPanelWidth,
                         kTitleHeight + static_cast<int>(i / columns) * kPanelHeight, kPanelWidth, kPanelHeight);
    DrawHistogramPanel(image, panel, names[i], pooled_m[names[i]]);
  }
  WritePng(path, image, true);
}

void WriteLocalizationMap(const std::string& path, const garden::OccupancyMap& map,
                          const garden::OccupancyMap& true_map, const std::vector<LocalizationFrame>& frames,
                          const std::string& title) {
  MapCanvas canvas = DrawMapCanvas(path, map, true_map, kLegendRowHeight + 2 * kLegendMargin, title);
  std::vector<int> counts(OutcomeClasses().size(), 0);
  // Accepted fixes first, so that the frames where localization broke are drawn over them.
  for (int pass = 0; pass < 2; ++pass) {
    for (const LocalizationFrame& frame : frames) {
      const std::size_t k = OutcomeClassOf(frame.outcome);
      if ((k == 0) != (pass == 0) || !frame.position.allFinite()) continue;
      ++counts[k];
      cv::circle(canvas.image, FixedPoint(canvas.to_image(frame.position)), (k == 0 ? 3 : 4) << kSubpixelBits,
                 OutcomeClasses()[k].colour, cv::FILLED, cv::LINE_AA, kSubpixelBits);
    }
  }
  int x = kLegendMargin;
  const int y = canvas.legend_top + kLegendMargin + kLegendRowHeight / 2;
  for (std::size_t k = 0; k < counts.size(); ++k) {
    const std::string label = OutcomeClasses()[k].label + ": " + std::to_string(counts[k]);
    cv::circle(canvas.image, {x + 6, y}, 5, OutcomeClasses()[k].colour, cv::FILLED, cv::LINE_AA);
    PutText(canvas.image, label, {x + 18, y + 6}, 0.5, kInk);
    x += 18 + TextSize(label, 0.5, 1).width + 28;
  }
  WritePng(path, canvas.image, true);
}

std::vector<LocalizationFrame> ReadLocalizationCsv(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path, "cannot open the localization log");
  std::vector<LocalizationFrame> frames;
  std::string line;
  std::getline(file, line);  // the header
  for (int line_number = 2; std::getline(file, line); ++line_number) {
    // t, true_x, true_y, true_yaw, outcome: the fields before the quoted failure text.
    std::istringstream fields(line);
    std::string t, x, y, yaw, outcome;
    if (!std::getline(fields, t, ',') || !std::getline(fields, x, ',') || !std::getline(fields, y, ',') ||
        !std::getline(fields, yaw, ',') || !std::getline(fields, outcome, ',')) {
      throw InputError(path, "line " + std::to_string(line_number) + ": fewer than 5 fields");
    }
    const double nan = std::nan("");
    frames.push_back({x.empty() || y.empty()
                          ? Eigen::Vector2d(nan, nan)
                          : Eigen::Vector2d(std::strtod(x.c_str(), nullptr), std::strtod(y.c_str(), nullptr)),
                      outcome});
  }
  return frames;
}

std::vector<Eigen::Vector2d> ReadTumPositions(const std::string& path) {
  std::vector<Eigen::Vector2d> positions;
  for (const StampedPose& pose : ReadTum(path)) positions.push_back(pose.T.translation().head<2>());
  return positions;
}

}  // namespace trimbot::scenarios
