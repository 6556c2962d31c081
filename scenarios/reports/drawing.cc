#include "reports/drawing.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace trimbot::scenarios {

// Short, exact enough for people: 1, 0.95, 0.666667.
std::string FormatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

cv::Scalar HsvToRgb(double hue_deg, double saturation, double value) {
  const double h = std::fmod(std::fmod(hue_deg, 360.0) + 360.0, 360.0) / 60.0;
  const double chroma = value * saturation;
  const double x = chroma * (1.0 - std::abs(std::fmod(h, 2.0) - 1.0));
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(h)) {
    case 0: r = chroma, g = x; break;
    case 1: r = x, g = chroma; break;
    case 2: g = chroma, b = x; break;
    case 3: g = x, b = chroma; break;
    case 4: r = x, b = chroma; break;
    default: r = chroma, b = x; break;
  }
  const double m = value - chroma;
  return cv::Scalar((r + m) * 255.0, (g + m) * 255.0, (b + m) * 255.0);
}

cv::Size TextSize(const std::string& text, double scale, int thickness) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, thickness, &baseline);
}

void PutText(cv::Mat& image, const std::string& text, cv::Point origin, double scale, const cv::Scalar& colour,
             int thickness) {
  cv::putText(image, text, origin, kFont, scale, colour, thickness, cv::LINE_AA);
}

void PutTextCentred(cv::Mat& image, const std::string& text, cv::Point centre, double scale, const cv::Scalar& colour,
                    int thickness) {
  const cv::Size size = TextSize(text, scale, thickness);
  PutText(image, text, {centre.x - size.width / 2, centre.y + size.height / 2}, scale, colour, thickness);
}

// Fixed-point pixel for the cv drawing functions; far-off points are clamped so the fixed-point
// arithmetic cannot overflow (cv clips the lines to the image anyway).
cv::Point FixedPoint(const cv::Point2d& pixel) {
  constexpr double kLimit = 1e6;
  return {static_cast<int>(std::lround(std::clamp(pixel.x, -kLimit, kLimit) * (1 << kSubpixelBits))),
          static_cast<int>(std::lround(std::clamp(pixel.y, -kLimit, kLimit) * (1 << kSubpixelBits)))};
}

std::string FormatFixed(double value, int decimals) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(decimals) << value;
  return out.str();
}

// 1, 2 or 5 times a power of ten, so that `range` holds about `ticks` steps.
double NiceStep(double range, int ticks) {
  const double raw = std::max(range, 1e-9) / ticks;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double multiple : {1.0, 2.0, 5.0}) {
    if (raw <= multiple * power) return multiple * power;
  }
  return 10.0 * power;
}

}  // namespace trimbot::scenarios
