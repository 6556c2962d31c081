#pragma once
// What the robot has seen of obstacles, as a rolling occupancy grid around it: log-odds per cell,
// raised where stereo saw an obstacle, lowered where it saw the ground through the cell (the low
// part of the ray to a ground point: a higher obstacle would have hidden that point), and decaying
// towards "unknown" with time so what is no longer seen is forgotten. Its cells lie on the prior
// map's lattice; MergedWith() adds its occupied cells to the prior map for the planner (which
// inflates them by the robot's radius and footprint).
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "trimbot/stack/occupancy_grid.h"

namespace trimbot::stack {

struct ObstacleLayerParameters {
  double size = 12.0;        // m, side of the square window centred on the robot
  double hit = 0.85;         // log-odds added to a cell stereo saw an obstacle in (one frame)
  double miss = -0.4;        // log-odds added to a cell seen free (one frame)
  double occupied = 1.2;     // log-odds above which a cell is an obstacle (p = 0.77)
  double limit = 3.5;        // |log-odds| is clamped here, so evidence can be overturned
  double decay_time = 30.0;  // s: log-odds fall by 1/e in this time without new evidence
  int min_points = 5;        // obstacle points in a cell in one frame for a hit (speckle)
};

// What one stereo pair saw, in the map frame.
struct ObstacleView {
  Eigen::Vector2d sensor = Eigen::Vector2d::Zero();  // camera position
  double sensor_height = 0.5;                        // m above the ground
  std::vector<Eigen::Vector2d> obstacles;            // obstacle points
  std::vector<Eigen::Vector2d> ground;               // ground points
};

// One frame's observation: every pair's view at one stamp (a cell seen by two pairs counts once).
struct ObstacleObservation {
  double stamp = 0.0;
  double min_obstacle_height = 0.1;  // m: what counts as an obstacle
  std::vector<ObstacleView> views;
};

class ObstacleLayer {
 public:
  // The window's cells lie on `lattice`'s cells (same resolution and alignment).
  ObstacleLayer(const OccupancyGrid& lattice, const ObstacleLayerParameters& parameters);

  void Integrate(const ObstacleObservation& observation);

  double LogOdds(const Eigen::Vector2d& point) const;  // 0 (unknown) outside the window
  bool Occupied(const Eigen::Vector2d& point) const { return LogOdds(point) > parameters_.occupied; }
  int OccupiedCells() const;
  // The prior map with this layer's occupied cells added (same size, resolution and origin).
  OccupancyGrid MergedWith(const OccupancyGrid& prior) const;

  const cv::Mat& log_odds() const { return log_odds_; }      // CV_32F, row 0 = smallest y
  const Eigen::Vector2d& origin() const { return origin_; }  // window's bottom-left corner, map frame
  double resolution() const { return resolution_; }

 private:
  void Recentre(const Eigen::Vector2d& centre);
  std::optional<cv::Point> CellOf(const Eigen::Vector2d& point) const;  // (column, row) in the window

  ObstacleLayerParameters parameters_;
  double resolution_;
  Eigen::Vector2d lattice_origin_;
  int cells_;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  cv::Mat log_odds_;
  std::optional<double> last_stamp_;
};

}  // namespace trimbot::stack
