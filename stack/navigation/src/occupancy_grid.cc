#include "trimbot/stack/occupancy_grid.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "trimbot/common/input_error.h"
#include "trimbot/common/yaml_reader.h"

namespace trimbot::stack {

OccupancyGrid OccupancyGrid::LoadMapServer(const std::string& yaml_path) {
  const YamlMap yaml = YamlMap::LoadFile(yaml_path);
  const std::string image_name = yaml.String("image");
  const double resolution = yaml.Number("resolution", 1e-3, 10.0, "m");
  const std::vector<double> origin = yaml.Numbers("origin", 3, -1e4, 1e4, "m");
  const bool negate = yaml.Has("negate") && yaml.Integer("negate", 0, 1) != 0;
  const double occupied_thresh = yaml.NumberOr("occupied_thresh", 0.65, 0.0, 1.0);
  // Cells between free_thresh and occupied_thresh are unknown; the robot treats them as occupied.
  const double free_thresh = yaml.NumberOr("free_thresh", 0.196, 0.0, 1.0);
  if (free_thresh > occupied_thresh) yaml.Fail("free_thresh", "must not exceed occupied_thresh");
  yaml.String("mode", "trinary");
  yaml.RejectUnknownKeys();

  std::filesystem::path image_path(image_name);
  if (image_path.is_relative()) image_path = std::filesystem::path(yaml_path).parent_path() / image_path;
  const cv::Mat grey = cv::imread(image_path.string(), cv::IMREAD_GRAYSCALE);
  if (grey.empty())
    throw InputError(image_path.string(), "cannot read the map image (referenced by " + yaml_path + ")");

  // map_server: p = (255 - value) / 255 is the occupancy probability (value / 255 when negated).
  cv::Mat occupied(grey.size(), CV_8U);
  for (int r = 0; r < grey.rows; ++r) {
    for (int c = 0; c < grey.cols; ++c) {
      const double value = grey.at<uchar>(r, c) / 255.0;
      const double p = negate ? value : 1.0 - value;
      occupied.at<uchar>(r, c) = p >= free_thresh ? 255 : 0;
    }
  }
  return OccupancyGrid(occupied, resolution, {origin[0], origin[1]});
}

OccupancyGrid::OccupancyGrid(const cv::Mat& occupied, double resolution, const Eigen::Vector2d& origin)
    : resolution_(resolution), origin_(origin) {
  if (occupied.empty() || occupied.type() != CV_8U) throw std::invalid_argument("OccupancyGrid: needs a CV_8U image");
  occupied_ = occupied.clone();
  occupied_.setTo(255, occupied_ != 0);
  // Distance transform of the free cells: L2 distance in cells to the nearest occupied cell.
  cv::Mat free = occupied_ == 0;
  cv::distanceTransform(free, distance_, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  distance_ *= resolution_;
}

bool OccupancyGrid::Contains(const Eigen::Vector2d& point) const {
  const Eigen::Vector2d local = (point - origin_) / resolution_;
  return local.x() >= 0.0 && local.y() >= 0.0 && local.x() < occupied_.cols && local.y() < occupied_.rows;
}

cv::Point OccupancyGrid::Cell(const Eigen::Vector2d& point) const {
  const Eigen::Vector2d local = (point - origin_) / resolution_;
  return {static_cast<int>(std::floor(local.x())), occupied_.rows - 1 - static_cast<int>(std::floor(local.y()))};
}

Eigen::Vector2d OccupancyGrid::CellCentre(const cv::Point& cell) const {
  return origin_ + resolution_ * Eigen::Vector2d(cell.x + 0.5, occupied_.rows - 1 - cell.y + 0.5);
}

double OccupancyGrid::DistanceToObstacleAtCell(const Eigen::Vector2d& point) const {
  const Eigen::Vector2d local = (point - origin_) / resolution_;
  const int column = static_cast<int>(std::floor(local.x())), y = static_cast<int>(std::floor(local.y()));
  if (column < 0 || y < 0 || column >= distance_.cols || y >= distance_.rows) return 0.0;
  return static_cast<double>(distance_.at<float>(distance_.rows - 1 - y, column));
}

double OccupancyGrid::DistanceToObstacle(const Eigen::Vector2d& point) const {
  if (!Contains(point)) return 0.0;
  // Bilinear interpolation between the four surrounding cell centres.
  const Eigen::Vector2d local = (point - origin_) / resolution_ - Eigen::Vector2d(0.5, 0.5);
  const int c0 = std::clamp(static_cast<int>(std::floor(local.x())), 0, distance_.cols - 1);
  const int y0 = std::clamp(static_cast<int>(std::floor(local.y())), 0, distance_.rows - 1);
  const int c1 = std::min(c0 + 1, distance_.cols - 1);
  const int y1 = std::min(y0 + 1, distance_.rows - 1);
  const double fx = std::clamp(local.x() - c0, 0.0, 1.0);
  const double fy = std::clamp(local.y() - y0, 0.0, 1.0);
  auto at = [&](int c, int y) { return static_cast<double>(distance_.at<float>(distance_.rows - 1 - y, c)); };
  const double d =
      (1 - fx) * (1 - fy) * at(c0, y0) + fx * (1 - fy) * at(c1, y0) + (1 - fx) * fy * at(c0, y1) + fx * fy * at(c1, y1);
  // Inside an occupied cell the distance is 0 whatever the neighbours say.
  const cv::Point cell = Cell(point);
  return occupied_.at<uchar>(cell.y, cell.x) ? 0.0 : d;
}

}  // namespace trimbot::stack
