#include "trimbot/stack/base_outline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace trimbot::stack {
namespace {

// Distance from a point to the axis-aligned rectangle [-half, half] (0 inside).
double DistanceToBox(const Eigen::Vector2d& p, const Eigen::Vector2d& half) {
  return Eigen::Vector2d(std::max(std::abs(p.x()) - half.x(), 0.0), std::max(std::abs(p.y()) - half.y(), 0.0)).norm();
}

// Whether the projections of two convex quadrilaterals on `axis` are apart.
bool SeparatedAlong(const std::array<Eigen::Vector2d, 4>& a, const std::array<Eigen::Vector2d, 4>& b,
                    const Eigen::Vector2d& axis) {
  double a_low = std::numeric_limits<double>::infinity(), a_high = -a_low, b_low = a_low, b_high = -a_low;
  for (const auto& p : a) {
    a_low = std::min(a_low, p.dot(axis));
    a_high = std::max(a_high, p.dot(axis));
  }
  for (const auto& p : b) {
    b_low = std::min(b_low, p.dot(axis));
    b_high = std::max(b_high, p.dot(axis));
  }
  return a_high < b_low || b_high < a_low;
}

}  // namespace

BaseOutline::BaseOutline(const Eigen::Vector2d& min, const Eigen::Vector2d& max) : min_(min), max_(max) {
  for (const Eigen::Vector2d& corner :
       {min, max, Eigen::Vector2d(min.x(), max.y()), Eigen::Vector2d(max.x(), min.y())}) {
    reach_ = std::max(reach_, corner.norm());
  }
}

double BaseOutline::Clearance(const OccupancyGrid& map, const Pose2& pose, double enough) const {
  const double r = map.resolution();
  const Eigen::Vector2d half = 0.5 * (max_ - min_);
  const Eigen::Vector2d centre = FromFrame(pose, 0.5 * (min_ + max_));
  const double circumradius = half.norm();
  // A bound from the centre alone: every occupied cell's square is at least the distance to its
  // centre less half its diagonal away, and the map's edge (beyond it all is occupied) as far as it is.
  const Eigen::Vector2d low_corner = map.origin(), high_corner = map.origin() + map.size();
  const double to_edge = std::min({centre.x() - low_corner.x(), high_corner.x() - centre.x(),
                                   centre.y() - low_corner.y(), high_corner.y() - centre.y()});
  const double to_cell = map.DistanceToObstacle(centre);
  const bool centre_free = map.Contains(centre) && to_cell > 0.0;
  const double bound = std::min(to_cell - M_SQRT1_2 * r, to_edge) - circumradius;
  if (centre_free && bound >= enough) return bound;

  // Exact: every cell whose square could come closer than both `enough` and the nearest occupied
  // cell's centre (an upper bound of the clearance) is measured, polygon to polygon, in the
  // outline's frame.
  const double limit = std::min(centre_free ? std::min(to_cell, std::max(to_edge, 0.0)) : 0.0, enough);
  // (The centre's distance is interpolated between cell centres: a cell more of slack.)
  const double search = std::max(limit, 0.0) + circumradius + M_SQRT1_2 * r + r;
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  const Eigen::Vector2d axis_x(c, s), axis_y(-s, c);  // the outline's axes in the map
  const std::array<Eigen::Vector2d, 4> box{Eigen::Vector2d(-half.x(), -half.y()), Eigen::Vector2d(half.x(), -half.y()),
                                           Eigen::Vector2d(half.x(), half.y()), Eigen::Vector2d(-half.x(), half.y())};
  // The cell square's half-edge vectors in the outline's frame (the map's x and y axes there).
  const Eigen::Vector2d cell_x = 0.5 * r * Eigen::Vector2d(c, -s), cell_y = 0.5 * r * Eigen::Vector2d(s, c);
  const cv::Mat& occupied = map.occupied();
  const cv::Point low = map.Cell(centre - Eigen::Vector2d::Constant(search));
  const cv::Point high = map.Cell(centre + Eigen::Vector2d::Constant(search));
  double clearance = std::isfinite(enough) ? std::max(enough, bound) : std::numeric_limits<double>::infinity();
  for (int row = high.y; row <= low.y; ++row) {  // rows grow downwards (map_server images)
    for (int column = low.x; column <= high.x; ++column) {
      const bool inside_grid = column >= 0 && row >= 0 && column < occupied.cols && row < occupied.rows;
      if (inside_grid && occupied.at<uchar>(row, column) == 0) continue;
      const Eigen::Vector2d d = map.CellCentre({column, row}) - centre;
      const Eigen::Vector2d u(d.dot(axis_x), d.dot(axis_y));  // the cell's centre in the outline's frame
      if (DistanceToBox(u, half) - M_SQRT1_2 * r >= clearance) continue;
      const std::array<Eigen::Vector2d, 4> cell{u - cell_x - cell_y, u + cell_x - cell_y, u + cell_x + cell_y,
                                                u - cell_x + cell_y};
      const bool apart = SeparatedAlong(box, cell, Eigen::Vector2d::UnitX()) ||
                         SeparatedAlong(box, cell, Eigen::Vector2d::UnitY()) || SeparatedAlong(box, cell, cell_x) ||
                         SeparatedAlong(box, cell, cell_y);
      double distance;
      if (apart) {
        // Between convex polygons apart, the nearest pair has a vertex of one of them.
        distance = std::numeric_limits<double>::infinity();
        for (const auto& v : cell) distance = std::min(distance, DistanceToBox(v, half));
        for (const auto& v : box) {
          const Eigen::Vector2d w = v - u;  // in the cell's frame: its axes are cell_x, cell_y
          distance = std::min(distance, DistanceToBox({w.dot(cell_x.normalized()), w.dot(cell_y.normalized())},
                                                      Eigen::Vector2d::Constant(0.5 * r)));
        }
      } else {
        // Overlapping: how deep the cell's centre lies inside the outline (at least a little).
        const double depth = std::min(half.x() - std::abs(u.x()), half.y() - std::abs(u.y()));
        distance = std::min(-depth, -1e-9);
      }
      clearance = std::min(clearance, distance);
    }
  }
  return clearance;
}

double BaseOutline::TurnClearance(const OccupancyGrid& map, const Pose2& pose, double to_yaw, double step,
                                  double enough) const {
  const double turn = WrapAngle(to_yaw - pose.yaw);
  const int steps = std::max(1, static_cast<int>(std::ceil(std::abs(turn) * reach_ / std::max(step, 1e-4))));
  // Between two checks a point of the outline travels at most this far from where it was checked.
  const double travel = 0.5 * std::abs(turn) / steps * reach_;
  double clearance = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= steps; ++k) {
    const Pose2 turned{pose.x, pose.y, pose.yaw + turn * static_cast<double>(k) / steps};
    clearance = std::min(clearance, Clearance(map, turned, enough + travel));
  }
  return clearance - (steps > 0 && turn != 0.0 ? travel : 0.0);
}

}  // namespace trimbot::stack
