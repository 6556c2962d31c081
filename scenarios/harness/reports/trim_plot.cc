#include "reports/trim_plot.h"

#include <algorithm>

#include "reports/drawing.h"
#include "reports/output_files.h"

namespace trimbot::scenarios {
namespace {

constexpr double kTolerance = 0.02;  // m: the cut criterion's (van Marrewijk et al. 2022)
constexpr int kScale = 4;            // pixels per column
const cv::Scalar kCutIn(30, 90, 200), kWithin(60, 170, 70), kOnTheGround(190, 190, 190);

cv::Scalar DistanceColour(double d) {
  if (d < -kTolerance) return kCutIn;
  if (d <= kTolerance) return kWithin;
  const double f = std::min(1.0, (d - kTolerance) / 0.08);
  return cv::Scalar(230, 220 * (1.0 - f), 30);
}

cv::Mat DistanceMap(const garden::Foliage& foliage, const std::string& title) {
  const int top = 30;
  cv::Mat image(foliage.rings() * kScale + top, foliage.segments() * kScale, CV_8UC3, kWhite);
  for (int i = 0; i < foliage.columns(); ++i) {
    const int row = i / foliage.segments(), column = i % foliage.segments();
    cv::rectangle(image, cv::Rect(column * kScale, top + row * kScale, kScale, kScale),
                  foliage.OnTheGround(i, kTolerance) ? kOnTheGround : DistanceColour(foliage.height(i)), cv::FILLED);
  }
  PutText(image, title, {6, 20}, 0.5, kInk);
  return image;
}

std::string Percent(double share) { return FormatFixed(100.0 * share, 1) + " %"; }

}  // namespace

void WriteTrimDistanceMap(const std::string& path, const garden::Foliage& before, const garden::Foliage& after) {
  const auto title = [](const std::string& when, const garden::Foliage& foliage) {
    const garden::CutQuality q = foliage.Measure(kTolerance);
    return when + ": " + Percent(q.surface_within_tolerance) + " within 2 cm (upper half " +
           Percent(q.upper_surface_within_tolerance) + ")";
  };
  cv::Mat image;
  cv::hconcat(DistanceMap(before, title("before", before)), cv::Mat(before.rings() * kScale + 30, 12, CV_8UC3, kWhite),
              image);
  cv::hconcat(image, DistanceMap(after, title("after", after)), image);
  cv::Mat legend(40, image.cols, CV_8UC3, kWhite);
  Legend(legend, 20,
         {{"cut > 2 cm into the target", kCutIn},
          {"within 2 cm", kWithin},
          {"2-10 cm over", DistanceColour(0.05)},
          {"> 10 cm over", DistanceColour(1.0)},
          {"on the ground (not counted)", kOnTheGround}});
  cv::vconcat(image, legend, image);
  WritePng(path, image, true);
}

void WriteBeforeAfter(const std::string& path, const cv::Mat& before, const cv::Mat& after) {
  cv::Mat left = before.clone(), right = after.clone();
  PutText(left, "before", {10, 24}, 0.7, kWhite, 2);
  PutText(right, "after", {10, 24}, 0.7, kWhite, 2);
  cv::Mat image;
  cv::hconcat(left, right, image);
  WritePng(path, image, true);
}

}  // namespace trimbot::scenarios
