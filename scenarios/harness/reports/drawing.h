#pragma once
// Drawing helpers shared by the report plots (images are RGB, cv::Mat CV_8UC3).
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <string>
#include <utility>
#include <vector>

namespace trimbot::scenarios {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
const cv::Scalar kInk(30, 30, 30);
const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kAxis(60, 60, 60);  // plots' axes, frames and tick labels
constexpr int kSubpixelBits = 4;     // cv drawing functions take fixed-point points with this shift

// Short, exact enough for people: 1, 0.95, 0.666667.
std::string FormatNumber(double value);
std::string FormatFixed(double value, int decimals);
cv::Scalar HsvToRgb(double hue_deg, double saturation, double value);
cv::Size TextSize(const std::string& text, double scale, int thickness);
void PutText(cv::Mat& image, const std::string& text, cv::Point origin, double scale, const cv::Scalar& colour,
             int thickness = 1);
void PutTextCentred(cv::Mat& image, const std::string& text, cv::Point centre, double scale, const cv::Scalar& colour,
                    int thickness = 1);
// Fixed-point pixel for the cv drawing functions; far-off points are clamped so the fixed-point
// arithmetic cannot overflow (cv clips the lines to the image anyway).
cv::Point FixedPoint(const cv::Point2d& pixel);
// 1, 2 or 5 times a power of ten, so that `range` holds about `ticks` steps.
double NiceStep(double range, int ticks);

// A panel of a plot: x and y ranges mapped onto a rectangle of the image, with a y grid, tick
// labels and a title above it (y starts at 0 for ranges of errors, which are >= 0).
class Panel {
 public:
  Panel(cv::Mat& image, cv::Rect area, double x0, double x1, double y0, double y1, const std::string& label);
  cv::Point At(double x, double y) const;
  void Line(const std::vector<cv::Point2d>& points, const cv::Scalar& colour, int thickness);
  void Dots(const std::vector<cv::Point2d>& points, const cv::Scalar& colour, int radius = 2);
  void Horizontal(double y, const cv::Scalar& colour);

 private:
  cv::Mat& image_;
  cv::Rect area_;
  double x0_, x1_, y0_ = 0.0, y1_ = 1.0, step_ = 1.0;
};

// Grows [x0, x1] x [y0, y1] to hold the points.
void Extent(const std::vector<cv::Point2d>& points, double* x0, double* x1, double* y0, double* y1);
// A row of coloured line samples with their labels, from the left edge at height y.
void Legend(cv::Mat& image, int y, const std::vector<std::pair<std::string, cv::Scalar>>& entries);

}  // namespace trimbot::scenarios
