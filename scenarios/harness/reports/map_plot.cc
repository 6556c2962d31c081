#include "reports/map_plot.h"

#include <algorithm>
#include <cmath>

#include "reports/drawing.h"
#include "reports/output_files.h"

namespace trimbot::scenarios {

void WriteMapTopView(const std::string& path, const visual_localization::VisualMap& map,
                     const garden::OccupancyMap& objects, const std::string& title) {
  constexpr int kWidth = 1200, kTitle = 50;
  const double width_m = objects.occupied.cols * objects.resolution,
               height_m = objects.occupied.rows * objects.resolution;
  const double scale = kWidth / width_m;  // px per metre
  const int height = kTitle + static_cast<int>(std::lround(height_m * scale)) + 30;
  cv::Mat image(height, kWidth, CV_8UC3, kWhite);
  const auto to_pixel = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround((x - objects.origin.x()) * scale)),
                     kTitle + static_cast<int>(std::lround((objects.origin.y() + height_m - y) * scale)));
  };
  // The garden's objects as light grey footprints.
  cv::Mat occupied;
  cv::resize(objects.occupied, occupied, cv::Size(kWidth, height - kTitle - 30), 0, 0, cv::INTER_NEAREST);
  image(cv::Rect(0, kTitle, kWidth, occupied.rows)).setTo(cv::Scalar(205, 205, 205), occupied);
  // Points coloured by height: blue low (ground) to red high (bush tops).
  for (const auto& p : map.points) {
    const double hue = 240.0 - 240.0 * std::clamp(p.z() / 1.5, 0.0, 1.0);
    cv::circle(image, to_pixel(p.x(), p.y()), 1, HsvToRgb(hue, 0.9, 0.85), cv::FILLED);
  }
  // Keyframes: a dot and a short line along base_link's x axis.
  for (const auto& k : map.keyframes) {
    const Eigen::Vector3d t = k.T_map_base.translation(), x = k.T_map_base.linear().col(0);
    cv::line(image, to_pixel(t.x(), t.y()), to_pixel(t.x() + 0.3 * x.x(), t.y() + 0.3 * x.y()), kInk, 2, cv::LINE_AA);
    cv::circle(image, to_pixel(t.x(), t.y()), 4, kInk, cv::FILLED, cv::LINE_AA);
  }
  PutText(image, title, {12, 32}, 0.65, kInk, 2);
  PutText(image,
          "points coloured by height (blue 0 m .. red 1.5 m), keyframes black, objects grey, 1 px = " +
              FormatFixed(100.0 / scale, 1) + " cm",
          {12, height - 10}, 0.42, kInk);
  WritePng(path, image);
}

}  // namespace trimbot::scenarios
