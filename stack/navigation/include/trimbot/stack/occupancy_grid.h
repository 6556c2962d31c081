#pragma once
// The robot's prior map of the garden: a 2D occupancy grid in ROS map_server format (YAML + PNG),
// like the real robot's sketch map. It is what the robot believes, not the simulator's geometry.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>

namespace trimbot::stack {

class OccupancyGrid {
 public:
  // Loads a map_server YAML (image, resolution, origin, negate, occupied_thresh, free_thresh).
  // Unknown cells count as occupied. Throws InputError naming the file and the problem.
  static OccupancyGrid LoadMapServer(const std::string& yaml_path);
  // `occupied`: CV_8U, non-zero = occupied, row 0 = the map's top (largest y), as map_server PNGs.
  OccupancyGrid(const cv::Mat& occupied, double resolution, const Eigen::Vector2d& origin);

  // Distance in metres from a map point to the nearest occupied cell (0 inside one, and outside
  // the map), interpolated between cell centres.
  double DistanceToObstacle(const Eigen::Vector2d& point) const;
  // The same at the centre of the point's cell: no interpolation, for costs evaluated very often.
  double DistanceToObstacleAtCell(const Eigen::Vector2d& point) const;
  bool Contains(const Eigen::Vector2d& point) const;

  // Cell (column, row) holding a map point, and the map point at a cell's centre.
  cv::Point Cell(const Eigen::Vector2d& point) const;
  Eigen::Vector2d CellCentre(const cv::Point& cell) const;

  const cv::Mat& occupied() const { return occupied_; }
  double resolution() const { return resolution_; }
  const Eigen::Vector2d& origin() const { return origin_; }  // bottom-left corner of the map
  Eigen::Vector2d size() const { return {occupied_.cols * resolution_, occupied_.rows * resolution_}; }

 private:
  cv::Mat occupied_;  // CV_8U 0/255
  cv::Mat distance_;  // CV_32F, metres from each cell centre to the nearest occupied cell
  double resolution_ = 0.05;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
};

}  // namespace trimbot::stack
