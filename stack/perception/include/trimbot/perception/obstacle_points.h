#pragma once
// Obstacles from stereo geometry alone (no labels): a pair's cloud in base_link is split against
// the ground plane fitted to it into
//   obstacle points - between min_height and max_height above the ground: the robot would hit them;
//   ground points   - on the ground: the space between the camera and them is seen free, low down.
// Points whose depth is too uncertain (per-point covariance) and points on the robot itself are
// dropped. The result is plain data for the navigation's obstacle layer.
#include <Eigen/Core>
#include <vector>

#include "trimbot/perception/point_cloud.h"
#include "trimbot/perception/stereo.h"

namespace trimbot::perception {

struct ObstaclePointOptions {
  double min_height = 0.1;                     // m above the ground: lower is ground (the base drives over it)
  double max_height = 1.2;                     // m: higher passes over the robot (tree canopies)
  double ground_tolerance = 0.05;              // m: |height| below this is ground
  double max_position_sigma = 0.1;             // m: points with sqrt(trace(covariance)) above this are dropped
  Eigen::Vector2d robot_min = {-0.25, -0.35};  // m, base_link box of the robot itself (its base,
  Eigen::Vector2d robot_max = {0.65, 0.35};    //    ring and arm); points inside are not obstacles
  GroundFitOptions ground;
};

struct ObstaclePoints {
  Eigen::Vector3d sensor = Eigen::Vector3d::Zero();  // base_link position of the camera that saw them
  GroundPlane ground;                                // fitted (or base_link's z = 0 if none fitted)
  bool ground_fitted = false;
  std::vector<Eigen::Vector3d> obstacles;      // base_link
  std::vector<Eigen::Vector3d> ground_points;  // base_link
};

// `sensor`: where the cloud was seen from (the rectified left camera's origin), base_link.
ObstaclePoints FindObstaclePoints(const PointCloud& cloud, const Eigen::Vector3d& sensor,
                                  const ObstaclePointOptions& options = {});

}  // namespace trimbot::perception
