#pragma once
// Writers for the run's images: PNG (colour, 16-bit depth in mm, labels), written atomically.
#include <opencv2/core.hpp>
#include <string>

#include "trimbot/messages/sensor_messages.h"

namespace trimbot::scenarios {

// A camera image as a cv::Mat over its bytes (no copy: valid while `image` is), RGB or mono as
// its encoding says.
cv::Mat ImageView(const messages::Image& image);

// cv::Mat in RGB (or single channel) order -> PNG.
void WritePng(const std::string& path, const cv::Mat& image, bool rgb_order = true);
// Metres -> 16-bit PNG in millimetres (0 = no depth), the TUM RGB-D convention scaled to mm.
void WriteDepthPng(const std::string& path, const cv::Mat& depth_m);
// A colour picture of a class-label image, for people to look at.
cv::Mat ColouriseClasses(const cv::Mat& object_class);

}  // namespace trimbot::scenarios
