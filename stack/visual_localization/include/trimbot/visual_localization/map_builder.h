#pragma once
// Offline map building from a mapping drive: ring frames with survey poses of base_link (on the
// real robot the map was tied to a laser tracker; in the twin the drive's poses plus seeded
// noise). Stages, with plain data in between (as COLMAP's):
//   keyframes   a frame each `keyframe_distance` / `keyframe_angle` of survey motion
//   features    Upright-SIFT per camera image (grayscale)
//   matching    each keyframe against the next few, camera pairs that look the same way; ratio
//               test, then guided by the survey poses (epipolar angle)
//   tracks      matches joined into tracks (union-find), inconsistent ones dropped
//   points      triangulated from the survey poses (midpoint, checked by angle and depth)
//   adjustment  Ceres: bearing reprojection errors (Huber) of every observation, keyframe poses
//               held near the survey by priors (sigma from the survey); observations with a large
//               error afterwards are dropped and the map adjusted again
//   vocabulary  k-means words over the map's descriptors, for retrieval
#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/visual_localization/features.h"
#include "trimbot/visual_localization/visual_map.h"

namespace trimbot::visual_localization {

struct MapBuilderOptions {
  FeatureOptions features;
  double keyframe_distance = 0.3;                   // m of survey motion between keyframes
  double keyframe_angle = 10.0 * M_PI / 180;        // rad
  int match_next_keyframes = 3;                     // each keyframe is matched with this many following ones
  double max_camera_angle = 60.0 * M_PI / 180;      // rad between optical axes of two matched images
  double ratio = 0.8;                               // Lowe's ratio test
  double epipolar_angle = 0.015;                    // rad from the epipolar plane of the survey poses
  double survey_position_sigma = 0.02;              // m, prior of each keyframe's position
  double survey_rotation_sigma = 0.5 * M_PI / 180;  // rad
  double pixel_sigma = 1.0;                         // px
  double max_reprojection_error = 4.0;              // px: observations worse after adjustment are dropped
  double min_triangulation_angle = 1.0 * M_PI / 180;
  double max_depth = 25.0;  // m
  int vocabulary_words = 256;
  int adjustment_iterations = 30;
};

struct MapBuildStats {
  int frames = 0, keyframes = 0, images_matched = 0, matches = 0, tracks = 0, points = 0, observations = 0;
  int outlier_observations = 0;  // dropped after the first adjustment
  double mean_track_length = 0.0;
  double reprojection_rmse_px = 0.0;  // after the second adjustment, over the observations kept
  double seconds_features = 0.0, seconds_matching = 0.0, seconds_adjustment = 0.0, seconds_vocabulary = 0.0;
};

// Plain data between the stages.
using MappingImage = ImageFeatures;
struct MappingKeyframe {
  double stamp = 0.0;
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();  // survey pose
  std::vector<MappingImage> images;                              // per camera
};

class MapBuilder {
 public:
  MapBuilder(const robot::CameraRig& rig, const MapBuilderOptions& options);

  // Whether a frame at this survey pose would become a keyframe (so a renderer can skip others).
  bool WantsFrame(const Eigen::Isometry3d& T_map_base_survey) const;
  // Adds a ring frame with the survey pose of base_link at its stamp; returns whether it was kept.
  bool AddFrame(const messages::RingFrame& frame, const Eigen::Isometry3d& T_map_base_survey);

  VisualMap Build(const std::string& garden, MapBuildStats* stats);
  int keyframes() const { return static_cast<int>(keyframes_.size()); }

 private:
  robot::CameraRig rig_;
  MapBuilderOptions options_;
  std::vector<MappingKeyframe> keyframes_;
  MapBuildStats stats_;
};

}  // namespace trimbot::visual_localization
