#include "trimbot/stack/obstacle_layer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace trimbot::stack {

ObstacleLayer::ObstacleLayer(const OccupancyGrid& lattice, const ObstacleLayerParameters& parameters)
    : parameters_(parameters),
      resolution_(lattice.resolution()),
      lattice_origin_(lattice.origin()),
      cells_(std::max(1, static_cast<int>(std::lround(parameters.size / lattice.resolution())))) {
  if (!(parameters.size > 0.0) || !(parameters.decay_time > 0.0) || !(parameters.hit > 0.0) ||
      !(parameters.miss < 0.0) || !(parameters.limit > parameters.occupied)) {
    throw std::invalid_argument("ObstacleLayer: size and decay_time > 0, hit > 0 > miss, limit > occupied");
  }
  log_odds_ = cv::Mat::zeros(cells_, cells_, CV_32F);
  origin_ = lattice_origin_;
}

std::optional<cv::Point> ObstacleLayer::CellOf(const Eigen::Vector2d& point) const {
  const int column = static_cast<int>(std::floor((point.x() - origin_.x()) / resolution_));
  const int row = static_cast<int>(std::floor((point.y() - origin_.y()) / resolution_));
  if (column < 0 || row < 0 || column >= cells_ || row >= cells_) return std::nullopt;
  return cv::Point(column, row);
}

void ObstacleLayer::Recentre(const Eigen::Vector2d& centre) {
  const Eigen::Vector2d wanted = centre - Eigen::Vector2d::Constant(0.5 * cells_ * resolution_);
  // Snap to the lattice, then move the kept cells by whole cells.
  const Eigen::Vector2d snapped =
      lattice_origin_ + resolution_ * ((wanted - lattice_origin_) / resolution_).array().round().matrix();
  const int dx = static_cast<int>(std::lround((snapped.x() - origin_.x()) / resolution_));
  const int dy = static_cast<int>(std::lround((snapped.y() - origin_.y()) / resolution_));
  if (dx == 0 && dy == 0) return;
  cv::Mat moved = cv::Mat::zeros(cells_, cells_, CV_32F);
  const int x0 = std::max(0, dx), x1 = std::min(cells_, cells_ + dx);
  const int y0 = std::max(0, dy), y1 = std::min(cells_, cells_ + dy);
  if (x0 < x1 && y0 < y1) {
    log_odds_(cv::Range(y0, y1), cv::Range(x0, x1))
        .copyTo(moved(cv::Range(y0 - dy, y1 - dy), cv::Range(x0 - dx, x1 - dx)));
  }
  log_odds_ = moved;
  origin_ = snapped;
}

void ObstacleLayer::Integrate(const ObstacleObservation& observation) {
  const bool first = !last_stamp_;
  if (last_stamp_) {
    const double elapsed = std::max(0.0, observation.stamp - *last_stamp_);
    log_odds_ *= std::exp(-elapsed / parameters_.decay_time);
  }
  last_stamp_ = observation.stamp;
  if (observation.views.empty()) return;
  // Keep the robot in the middle half of the window.
  const Eigen::Vector2d robot = observation.views.front().sensor;
  const Eigen::Vector2d centre = origin_ + Eigen::Vector2d::Constant(0.5 * cells_ * resolution_);
  if (first || (robot - centre).cwiseAbs().maxCoeff() > 0.25 * cells_ * resolution_) Recentre(robot);

  cv::Mat hits = cv::Mat::zeros(cells_, cells_, CV_16U);
  cv::Mat seen_free = cv::Mat::zeros(cells_, cells_, CV_8U);
  for (const ObstacleView& view : observation.views) {
    for (const Eigen::Vector2d& point : view.obstacles) {
      if (const auto cell = CellOf(point)) {
        auto& count = hits.at<std::uint16_t>(*cell);
        if (count < 65535) ++count;
      }
    }
    // A ground point at distance r is seen along a ray that is below the obstacle height only over
    // its last min_height / sensor_height of the way: only that part is seen free.
    const double free_from =
        std::clamp(1.0 - observation.min_obstacle_height / std::max(view.sensor_height, 1e-6), 0.0, 1.0);
    for (const Eigen::Vector2d& end : view.ground) {
      const Eigen::Vector2d start = view.sensor + free_from * (end - view.sensor);
      const int steps = std::max(1, static_cast<int>(std::ceil((end - start).norm() / (0.5 * resolution_))));
      for (int i = 0; i <= steps; ++i) {
        if (const auto cell = CellOf(start + (static_cast<double>(i) / steps) * (end - start))) {
          seen_free.at<std::uint8_t>(*cell) = 1;
        }
      }
    }
  }
  for (int row = 0; row < cells_; ++row) {
    float* value = log_odds_.ptr<float>(row);
    const std::uint16_t* hit = hits.ptr<std::uint16_t>(row);
    const std::uint8_t* free = seen_free.ptr<std::uint8_t>(row);
    for (int column = 0; column < cells_; ++column) {
      double change = 0.0;
      if (hit[column] >= parameters_.min_points) {
        change = parameters_.hit;
      } else if (free[column] != 0) {
        change = parameters_.miss;
      }
      if (change != 0.0) {
        value[column] = static_cast<float>(std::clamp(value[column] + change, -parameters_.limit, parameters_.limit));
      }
    }
  }
}

double ObstacleLayer::LogOdds(const Eigen::Vector2d& point) const {
  const auto cell = CellOf(point);
  return cell ? log_odds_.at<float>(*cell) : 0.0;
}

int ObstacleLayer::OccupiedCells() const {
  cv::Mat occupied = log_odds_ > parameters_.occupied;
  return cv::countNonZero(occupied);
}

OccupancyGrid ObstacleLayer::MergedWith(const OccupancyGrid& prior) const {
  cv::Mat occupied = prior.occupied().clone();
  for (int row = 0; row < cells_; ++row) {
    const float* value = log_odds_.ptr<float>(row);
    for (int column = 0; column < cells_; ++column) {
      if (value[column] <= parameters_.occupied) continue;
      const Eigen::Vector2d centre = origin_ + resolution_ * Eigen::Vector2d(column + 0.5, row + 0.5);
      if (!prior.Contains(centre)) continue;
      occupied.at<std::uint8_t>(prior.Cell(centre)) = 255;
    }
  }
  return OccupancyGrid(occupied, prior.resolution(), prior.origin());
}

}  // namespace trimbot::stack
