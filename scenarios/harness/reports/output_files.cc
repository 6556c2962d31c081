#include "reports/output_files.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <iomanip>
#include <stdexcept>

#include "trimbot/common/atomic_file.h"

namespace trimbot::scenarios {

cv::Mat ImageView(const messages::Image& image) {
  return cv::Mat(image.height, image.width, image.encoding == "mono8" ? CV_8UC1 : CV_8UC3,
                 const_cast<std::uint8_t*>(image.data.data()));
}

void WritePng(const std::string& path, const cv::Mat& image, bool rgb_order) {
  cv::Mat out = image;
  if (rgb_order && image.channels() == 3) cv::cvtColor(image, out, cv::COLOR_RGB2BGR);
  std::vector<uchar> png;
  if (!cv::imencode(".png", out, png)) throw std::runtime_error(path + ": cannot encode PNG");
  WriteFileAtomically(path, std::string(png.begin(), png.end()));
}

void WriteDepthPng(const std::string& path, const cv::Mat& depth_m) {
  cv::Mat millimetres(depth_m.size(), CV_16U);
  for (int r = 0; r < depth_m.rows; ++r) {
    for (int c = 0; c < depth_m.cols; ++c) {
      const double mm = std::round(depth_m.at<float>(r, c) * 1000.0);
      millimetres.at<uint16_t>(r, c) = static_cast<uint16_t>(std::clamp(mm, 0.0, 65535.0));
    }
  }
  WritePng(path, millimetres, false);
}

cv::Mat ColouriseClasses(const cv::Mat& object_class) {
  // RGB colours per garden::ObjectClass value.
  static const cv::Vec3b kColours[] = {
      {0, 0, 0},     {120, 170, 90}, {20, 110, 40},  {200, 60, 110},  {40, 150, 120},
      {90, 200, 90}, {120, 80, 40},  {200, 160, 90}, {150, 150, 160}, {230, 220, 40},
  };
  cv::Mat out(object_class.size(), CV_8UC3);
  for (int r = 0; r < object_class.rows; ++r) {
    for (int c = 0; c < object_class.cols; ++c) {
      const uchar k = object_class.at<uchar>(r, c);
      out.at<cv::Vec3b>(r, c) = k < std::size(kColours) ? kColours[k] : cv::Vec3b(255, 0, 255);
    }
  }
  return out;
}

}  // namespace trimbot::scenarios
