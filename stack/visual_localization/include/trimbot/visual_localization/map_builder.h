#pragma once
// Offline map building from a mapping drive. Two ways to know the keyframes' poses while the map
// is built (`KeyframePoses`):
//   odometry  the robot's own log: each keyframe's wheel-inertial odometry pose. The map's frame
//             is the believed start; scale comes from the stereo pairs' calibrated baselines and
//             the wheels (a scale per stretch of travel: slip changes with the surface); drift
//             is closed by loop closure (place recognition with the map's own vocabulary, then
//             the ring's pose); the map is then tied to the garden by aligning its points with
//             the surveyed objects' shapes (as the real robot's map was aligned to the garden's
//             sketch map). No ground truth enters.
//   surveyed  a survey pose of base_link per keyframe (a laser tracker; in the twin the drive's
//             poses plus seeded noise), held as priors. For comparison and tests.
// Stages, with plain data in between (as COLMAP's):
//   keyframes   a frame each `keyframe_distance` / `keyframe_angle` of (odometry or survey) motion
//   features    Upright-SIFT per camera image (grayscale)
//   matching    each keyframe against the next few, camera pairs that look the same way; ratio
//               test, then the epipolar angle of the poses known so far; with odometry also the
//               two cameras of each stereo pair within a keyframe (calibrated epipolar geometry)
//   loops       (odometry) keyframes revisiting a place found by retrieval and verified by the
//               ring's pose against the provisional map; a pose graph (odometry + loop edges,
//               robust loss) moves the keyframes, then loop keyframes are matched too
//   tracks      matches joined into tracks (union-find), inconsistent ones dropped
//   points      triangulated (midpoint, checked by angle and depth)
//   adjustment  Ceres: bearing reprojection errors (Huber) of every observation, with survey
//               priors or odometry factors; observations with a large error afterwards are
//               dropped and the map adjusted again
//   tie         (odometry, when surveyed shapes are given) rigid planar alignment of the points to them
//   vocabulary  k-means words over the map's descriptors, for retrieval
#include <Eigen/Geometry>

#include <stdexcept>
#include <string>
#include <vector>

#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/visual_localization/features.h"
#include "trimbot/visual_localization/visual_map.h"

namespace trimbot::visual_localization {

// Raised whenever the builder makes a different map from the same drive and settings (a map cache
// keys on it). 2: tracks seen by one keyframe only are no longer map points.
constexpr int kMapBuilderVersion = 2;

enum class KeyframePoses { kOdometry, kSurveyed };
// "log" (odometry) or "surveyed": the map's builder. Inline: the scenario reader (fuzzed without
// this library) parses it too.
inline const char* ToString(KeyframePoses poses) { return poses == KeyframePoses::kOdometry ? "log" : "surveyed"; }
// "log" or "surveyed"; std::invalid_argument otherwise.
inline KeyframePoses KeyframePosesFromString(const std::string& name) {
  if (name == "log") return KeyframePoses::kOdometry;
  if (name == "surveyed") return KeyframePoses::kSurveyed;
  throw std::invalid_argument("unknown map builder '" + name + "' (log or surveyed)");
}

// How far the wheel-inertial odometry between two keyframes is trusted (1 sigma), in the frame of
// the first. Sources: the simulator's and D3.4's slip figures are percent-level along track (the
// scale per stretch absorbs the bias, these the rest); sideways slip in turns on grass costs the
// wheels ~10 deg in a few turns, which the gyro's heading avoids (design.md); the gyro's noise
// density and bias instability are in robot_parameters.yaml.
struct OdometryFactorOptions {
  double along_sigma = 0.005;            // m, plus:
  double along_sigma_per_m = 0.02;       // per m travelled
  double lateral_sigma = 0.005;          // m, plus:
  double lateral_sigma_per_m = 0.01;     // per m
  double yaw_sigma = 0.2 * M_PI / 180;   // rad, plus:
  double yaw_sigma_per_rad = 0.01;       // per rad turned
  double height_sigma = 0.01;            // m: the base stays on the ground
  double tilt_sigma = 0.5 * M_PI / 180;  // rad: roll and pitch change little between keyframes
  double scale_stretch = 2.0;            // m of travel per wheel-scale parameter
  double scale_prior_sigma = 0.1;        // of the first stretch's scale (around 1)
  double scale_change_sigma = 0.02;      // between neighbouring stretches (surfaces change it)
};

struct LoopClosureOptions {
  double min_travel = 3.0;            // m travelled since the candidate: nearer ones are neighbours
  double search_radius = 2.0;         // m around the query's odometry position
  double search_radius_per_m = 0.05;  // plus this much per m travelled since the candidate (drift)
  int candidates = 5;                 // retrieved keyframes verified per query
  int min_inliers = 50;               // D3.4, Table 4: a retrieval with >= 50 verified matches is correct
  double position_sigma = 0.03;       // m, of a loop edge (the ring's pose at a few metres)
  double rotation_sigma = 0.5 * M_PI / 180;
  // Cauchy scale (sigmas) of a loop edge's 6 residuals: sqrt of chi-square(6 dof, 95 %) = 12.59.
  // A loop whose residual after the pose graph lies beyond it has a weight under 0.5 and is dropped.
  double loss_scale = 3.548;
};

// An object of the garden as the user surveyed it (a hedge as a box, a bush as an ellipsoid, a
// trunk as a cylinder), in the garden's frame: what a log-built map is tied to.
struct SurveyedShape {
  enum class Kind { kBox, kCylinder, kEllipsoid };
  Kind kind = Kind::kBox;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // m
  Eigen::Vector3d size = Eigen::Vector3d::Ones();    // m, full extents along the shape's own axes
  double yaw = 0.0;                                  // rad about z
  // Signed distance (m) of a point to the surface: negative inside (exact for the box, a first-order
  // estimate for the others).
  double SignedDistance(const Eigen::Vector3d& point) const;
};

struct TieOptions {
  double min_height = 0.1;  // m: map points above the ground (the lawn is not surveyed)
  // m: a point further than this from every shape is not used (a start put down 10 cm / 3 deg
  // off is 0.5 m off 10 m away)...
  double start_distance = 1.0;
  double end_distance = 0.15;  // ...shrinking to this over the iterations
  double huber = 0.03;         // m: foliage's irregularity and the survey's 2 cm per point
  int iterations = 20;
};

struct MapBuilderOptions {
  KeyframePoses poses = KeyframePoses::kOdometry;
  FeatureOptions features;
  double keyframe_distance = 0.3;                   // m of motion between keyframes
  double keyframe_angle = 10.0 * M_PI / 180;        // rad
  int match_next_keyframes = 3;                     // each keyframe is matched with this many following ones
  double max_camera_angle = 60.0 * M_PI / 180;      // rad between optical axes of two matched images
  double ratio = 0.8;                               // Lowe's ratio test
  double epipolar_angle = 0.015;                    // rad from the epipolar plane of the poses
  double odometry_epipolar_angle = 0.03;            // rad, before the odometry's drift is corrected
  double survey_position_sigma = 0.02;              // m, prior of each keyframe's position (surveyed)
  double survey_rotation_sigma = 0.5 * M_PI / 180;  // rad
  OdometryFactorOptions odometry;
  LoopClosureOptions loops;
  TieOptions tie;
  double pixel_sigma = 1.0;             // px
  double max_reprojection_error = 4.0;  // px: observations worse after adjustment are dropped
  double min_triangulation_angle = 1.0 * M_PI / 180;
  double max_depth = 25.0;     // m
  int min_shared_points = 20;  // between consecutive keyframes, or the step is a gap
  int vocabulary_words = 256;
  int adjustment_iterations = 30;
};

struct MapBuildStats {
  int frames = 0, keyframes = 0, images_matched = 0, matches = 0, tracks = 0, points = 0, observations = 0;
  int stereo_matches = 0;                   // within a keyframe, between the two cameras of a pair
  int single_keyframe_tracks = 0;           // seen by one keyframe's stereo pair only: not map points
  int outlier_observations = 0;             // dropped after the first adjustment
  int loops_tried = 0, loops_accepted = 0;  // verified loop candidates, edges kept
  // Keyframe steps (k-1 -> k, listed by k) that share fewer than `min_shared_points` map points:
  // only the odometry bridges them (a camera outage, a blank view, frames missing from the log).
  std::vector<int> gaps;
  int scale_stretches = 0;
  double scale_min = 1.0, scale_max = 1.0;  // the wheels' scale per stretch (ground / wheel distance)
  double mean_track_length = 0.0;
  double reprojection_rmse_px = 0.0;                         // after the second adjustment, over the observations kept
  int tie_points = 0;                                        // map points used by the tie to the surveyed shapes
  double tie_residual_median = 0.0;                          // m, their distance to the outlines afterwards
  Eigen::Vector3d tie_correction = Eigen::Vector3d::Zero();  // x, y (m), yaw (rad) applied to the map
  double seconds_features = 0.0, seconds_matching = 0.0, seconds_loops = 0.0, seconds_adjustment = 0.0,
         seconds_vocabulary = 0.0;
};

// A loop closure found: keyframe `query` seen again at keyframe `match` (earlier), with the
// relative pose the ring's pose estimate gave.
struct LoopEdge {
  int query = 0, match = 0, inliers = 0;
  Eigen::Isometry3d T_match_query = Eigen::Isometry3d::Identity();
  double weight = 1.0;  // the robust loss's weight after the pose graph (near 0: rejected)
};

// Plain data between the stages.
using MappingImage = ImageFeatures;
struct MappingKeyframe {
  double stamp = 0.0;
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();  // current estimate
  Eigen::Isometry3d T_prior = Eigen::Isometry3d::Identity();     // survey pose, or odometry pose
  std::vector<MappingImage> images;                              // per camera
};

class MapBuilder {
 public:
  MapBuilder(const robot::CameraRig& rig, const MapBuilderOptions& options);

  // Whether a frame at this (odometry or survey) pose would become a keyframe (so a renderer can
  // skip others).
  bool WantsFrame(const Eigen::Isometry3d& T_map_base) const;
  // Adds a ring frame with the pose of base_link at its stamp (the odometry's in the frame of the
  // believed start, or the survey's); returns whether it was kept.
  bool AddFrame(const messages::RingFrame& frame, const Eigen::Isometry3d& T_map_base);
  // Adds a keyframe whose features are extracted already (per camera; empty for a missing camera).
  void AddKeyframe(double stamp, std::vector<MappingImage> images, const Eigen::Isometry3d& T_map_base);
  // The surveyed objects (the garden's frame), to which an odometry map is tied. Without them the
  // odometry map's frame stays the believed start's.
  void SetSurveyedShapes(std::vector<SurveyedShape> shapes) { shapes_ = std::move(shapes); }

  VisualMap Build(const std::string& garden, MapBuildStats* stats);
  int keyframes() const { return static_cast<int>(keyframes_.size()); }
  // After Build: the keyframes (final poses and the priors they started from) and the loops.
  const std::vector<MappingKeyframe>& keyframe_data() const { return keyframes_; }
  const std::vector<LoopEdge>& loops() const { return loops_; }

 private:
  robot::CameraRig rig_;
  MapBuilderOptions options_;
  std::vector<MappingKeyframe> keyframes_;
  std::vector<SurveyedShape> shapes_;
  std::vector<LoopEdge> loops_;
  MapBuildStats stats_;
};

}  // namespace trimbot::visual_localization
