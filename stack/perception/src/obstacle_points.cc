#include "trimbot/perception/obstacle_points.h"

#include <Eigen/Eigenvalues>

namespace trimbot::perception {

ObstaclePoints FindObstaclePoints(const PointCloud& cloud, const Eigen::Vector3d& sensor,
                                  const ObstaclePointOptions& options) {
  ObstaclePoints out;
  out.sensor = sensor;
  // The robot stands on its wheels: the ground near base_link's z = 0 is the fallback when too
  // little ground is seen to fit a plane (e.g. a wall fills the view).
  if (const auto plane = FitGroundPlane(cloud, options.ground)) {
    out.ground = *plane;
    out.ground_fitted = true;
  }
  const double max_variance = options.max_position_sigma * options.max_position_sigma;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.points[i];
    if (p.x() > options.robot_min.x() && p.x() < options.robot_max.x() && p.y() > options.robot_min.y() &&
        p.y() < options.robot_max.y()) {
      continue;
    }
    // A stereo point's variance is mostly along its viewing ray and grows with depth^4.
    if (cloud.covariances[i].trace() > max_variance) continue;
    const double height = out.ground.Distance(p);
    if (std::abs(height) < options.ground_tolerance) {
      out.ground_points.push_back(p);
    } else if (height >= options.min_height && height <= options.max_height) {
      out.obstacles.push_back(p);
    }
  }
  return out;
}

}  // namespace trimbot::perception
