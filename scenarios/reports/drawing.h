#pragma once
// Drawing helpers shared by the report plots (images are RGB, cv::Mat CV_8UC3).
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <string>

namespace trimbot::scenarios {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
const cv::Scalar kInk(30, 30, 30);
const cv::Scalar kWhite(255, 255, 255);
constexpr int kSubpixelBits = 4;  // cv drawing functions take fixed-point points with this shift

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

}  // namespace trimbot::scenarios
