#pragma once
// The map builder's optimisation stages (internal to trimbot_visual_localization): bundle
// adjustment with survey priors or odometry factors, and the pose graph that closes loops.
#include <Eigen/Geometry>

#include <vector>

#include "trimbot/robot/camera_rig.h"
#include "trimbot/visual_localization/map_builder.h"

namespace trimbot::visual_localization::mapping {

// One feature of one image of one keyframe.
struct FeatureRef {
  int keyframe = 0, camera = 0, feature = 0;
};
using Track = std::vector<FeatureRef>;

struct PointTrack {
  Eigen::Vector3d position;
  Track track;
};

// The wheels' scale per stretch of odometry travel (ground distance / wheel distance), and which
// stretch each keyframe step (k-1 -> k) falls in.
struct WheelScales {
  std::vector<double> scale;
  std::vector<int> stretch_of_step;  // [k]: of the step into keyframe k (entry 0 unused)
};
WheelScales MakeWheelScales(const std::vector<MappingKeyframe>& keyframes, const OdometryFactorOptions& options);

// Bundle adjustment of keyframe poses and points: reprojection errors of every observation, and
// the poses held by survey priors (surveyed) or by odometry factors between consecutive keyframes
// with the wheel scales and keyframe 0 fixed (odometry). Updates the keyframes' T_map_base, the
// points and the scales; returns the RMS reprojection error in pixels and each observation's
// error (px; points in order, each point's track in order) in `errors`.
double Adjust(const robot::CameraRig& rig, const MapBuilderOptions& options, std::vector<MappingKeyframe>& keyframes,
              std::vector<PointTrack>& points, WheelScales& scales, std::vector<double>* errors);

// Pose graph over the keyframes: consecutive keyframes held to their present relative poses (with
// the odometry's sigmas), loop edges with a Cauchy loss; keyframe 0 fixed. Updates T_map_base and
// each loop's weight.
void OptimizePoseGraph(const MapBuilderOptions& options, std::vector<MappingKeyframe>& keyframes,
                       std::vector<LoopEdge>& loops);

// Rigid planar alignment of the map's points above the ground to the surveyed shapes (iteratively
// reweighted Gauss-Newton on the points' signed distances, Huber weights, a shrinking distance
// gate). Returns T (x, y, yaw) that maps the map into the shapes' frame; `used` and `median`
// report the points used in the last iteration and their distance.
Eigen::Vector3d TieToShapes(const std::vector<PointTrack>& points, const std::vector<SurveyedShape>& shapes,
                            const TieOptions& options, int* used, double* median);

}  // namespace trimbot::visual_localization::mapping
