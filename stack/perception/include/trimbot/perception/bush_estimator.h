#pragma once
// Where a bush stands relative to the robot, from stereo geometry alone (no labels): the points of
// a pair's cloud near where the bush is expected, above the ground, in one foliage blob, are fitted with the bush's
// surveyed shape - an ellipsoid, an upright elliptic cylinder or a box with the garden map's
// extents and yaw - free in position and in overall scale (it has grown, or been cut, since the survey),
// robustly (Huber loss, Ceres), then fitted again on the points near the first fit (which drops a
// neighbour's foliage the first gate let in). The shape prior is what makes one viewpoint enough:
// a single side of a bush does not tell its depth (see the reference's Figure 19).
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/perception/point_cloud.h"
#include "trimbot/perception/stereo.h"

namespace trimbot::perception {

// A bush's shape as the survey knows it, in the frame of the fit (base_link).
struct BushShape {
  enum class Kind { kEllipsoid, kCylinder, kBox };  // the garden's shapes
  Kind kind = Kind::kEllipsoid;
  Eigen::Vector3d size = Eigen::Vector3d(0.7, 0.7, 0.6);  // m, full extents along its own x, y, z
  double base_height = 0.0;                               // m above the ground where the foliage starts
  double yaw = 0.0;                                       // rad, of its x axis in the fit's frame
  // m: half the larger horizontal extent.
  double Radius() const { return 0.5 * std::max(size.x(), size.y()); }
  // m from the centre to the outline a standoff towards `bearing` (rad, the frame of `yaw`) keeps
  // its gap from: an ellipsoid's or cylinder's elliptic outline there (an elongated bush seen from
  // its long side is half its short extent deep, not half its long one); a box's Radius() (its
  // standoffs face its corners, where the blade cuts the two faces beside them).
  double StandoffRadius(double bearing) const;
};

struct BushFitOptions {
  double gate = 0.3;                 // m: points farther than this outside the expected outline are not the bush
  double blob_cell = 0.04;           // m: grid of the foliage blobs (a gap this wide splits two bushes)
  double refit_gate = 0.1;           // m: the second fit keeps points this close to the first's surface
  double min_height = 0.05;          // m above the ground: lower is grass
  double max_position_sigma = 0.25;  // m: points with sqrt(trace(covariance)) above this are dropped
  int min_points = 80;               // fewer in the gate: no estimate
  int max_points = 3000;             // more are thinned evenly (the fit's time is linear in them)
  double huber = 0.02;               // m: residuals beyond this count linearly (leaves, outgrowth)
  double scale_sigma = 0.5;          // prior on the scale: 1 +- this (a season adds up to ~15 cm to a
                                     // ~0.35 m radius; outgrowth is irregular, not a scaling)
  double min_scale = 0.6, max_scale = 1.6;
};

struct BushEstimate {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  // m, the shape's vertical axis in the fit's frame
  double scale = 1.0;                                // fitted size / surveyed size
  int points = 0;                                    // points of the final fit
  double rms = 0.0;              // m: root mean square of the final fit's residuals (robust part excluded)
  double inlier_fraction = 0.0;  // of the final fit's points within `huber` of the surface
};

// Fits `shape` to the points of `cloud` (base_link, with covariances) above `ground`, starting at
// `expected_centre`. nullopt with the reason in `*failure` when too few points are in the gate or
// the fit does not converge.
std::optional<BushEstimate> FitBush(const PointCloud& cloud, const GroundPlane& ground, const BushShape& shape,
                                    const Eigen::Vector2d& expected_centre, const BushFitOptions& options = {},
                                    std::string* failure = nullptr);

}  // namespace trimbot::perception
