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
    case 0:
      r = chroma, g = x;
      break;
    case 1:
      r = x, g = chroma;
      break;
    case 2:
      g = chroma, b = x;
      break;
    case 3:
      g = x, b = chroma;
      break;
    case 4:
      r = x, b = chroma;
      break;
    default:
      r = chroma, b = x;
      break;
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

namespace {
const cv::Scalar kGrid(225, 225, 225);
}  // namespace

Panel::Panel(cv::Mat& image, cv::Rect area, double x0, double x1, double y0, double y1, const std::string& label)
    : image_(image), area_(area), x0_(x0), x1_(x1 > x0 ? x1 : x0 + 1.0) {
  const double pad = 0.08 * std::max(1e-6, y1 - y0);
  step_ = NiceStep(y1 - y0 + 2.0 * pad, 4);
  y0_ = std::floor((y0 >= 0.0 ? std::max(0.0, y0 - pad) : y0 - pad) / step_) * step_;  // errors stay >= 0
  y1_ = std::ceil((y1 + pad) / step_) * step_;
  for (double v = y0_; v <= y1_ + 1e-9 * step_; v += step_) {
    cv::line(image_, At(x0_, v), At(x1_, v), kGrid, 1);
    const std::string text = FormatNumber(std::round(v / step_) * step_);
    PutText(image_, text, {area_.x - 6 - TextSize(text, 0.35, 1).width, At(x0_, v).y + 4}, 0.35, kAxis);
  }
  cv::rectangle(image_, area_, kAxis, 1);
  PutText(image_, label, {area_.x + 4, area_.y - 5}, 0.4, kInk);
}

cv::Point Panel::At(double x, double y) const {
  return {area_.x + static_cast<int>(std::lround((x - x0_) / (x1_ - x0_) * area_.width)),
          area_.y + area_.height - static_cast<int>(std::lround((y - y0_) / (y1_ - y0_) * area_.height))};
}

void Panel::Line(const std::vector<cv::Point2d>& points, const cv::Scalar& colour, int thickness) {
  for (std::size_t i = 1; i < points.size(); ++i) {
    cv::line(image_, At(points[i - 1].x, points[i - 1].y), At(points[i].x, points[i].y), colour, thickness,
             cv::LINE_AA);
  }
}

void Panel::Dots(const std::vector<cv::Point2d>& points, const cv::Scalar& colour, int radius) {
  for (const auto& p : points) cv::circle(image_, At(p.x, p.y), radius, colour, cv::FILLED, cv::LINE_AA);
}

void Panel::Horizontal(double y, const cv::Scalar& colour) {
  cv::line(image_, At(x0_, y), At(x1_, y), colour, 1, cv::LINE_AA);
}

void Extent(const std::vector<cv::Point2d>& points, double* x0, double* x1, double* y0, double* y1) {
  for (const auto& p : points) {
    *x0 = std::min(*x0, p.x), *x1 = std::max(*x1, p.x), *y0 = std::min(*y0, p.y), *y1 = std::max(*y1, p.y);
  }
}

void Legend(cv::Mat& image, int y, const std::vector<std::pair<std::string, cv::Scalar>>& entries) {
  int x = 20;
  for (const auto& [text, colour] : entries) {
    cv::line(image, {x, y - 4}, {x + 22, y - 4}, colour, 3, cv::LINE_AA);
    PutText(image, text, {x + 28, y}, 0.42, kInk);
    x += 48 + TextSize(text, 0.42, 1).width;
  }
}

}  // namespace trimbot::scenarios
