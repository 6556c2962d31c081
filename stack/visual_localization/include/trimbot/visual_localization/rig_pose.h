#pragma once
// Absolute pose of the multi-camera ring from 2D-3D correspondences of all its cameras at once
// (the generalized absolute pose problem): OpenGV's GP3P minimal solver inside RANSAC, then a
// nonlinear refinement on the inliers, and a covariance from the inliers' angular residuals.
// RANSAC draws from a fixed seed: the same correspondences give the same pose.
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace trimbot::visual_localization {

struct Correspondence {
  int camera = 0;           // index into the rig's cameras
  Eigen::Vector3d bearing;  // unit ray in that camera's optical frame (z forward)
  Eigen::Vector3d point;    // map point (map frame)
};

struct RigPoseOptions {
  double inlier_angle = 0.004;  // rad: ~2 px at f = 500 px
  double angle_sigma = 0.002;   // rad: the bearings' noise, for the covariance
  int max_iterations = 500;
  int min_inliers = 12;
  // Inliers / correspondences below this: no pose (0: not checked). A consistent pose supported by
  // a small share of the matches is a wrong place more often than a right one (see stack.yaml).
  double min_inlier_ratio = 0.0;
};

struct RigPoseResult {
  bool success = false;
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  std::vector<int> inliers;  // indices into the correspondences
  Eigen::Matrix<double, 6, 6> covariance =
      Eigen::Matrix<double, 6, 6>::Identity();  // (rotation, translation) of base_link, left-perturbed
  std::string failure;                          // why not, when !success
};

// `T_base_camera[i]`: camera i's optical frame in base_link.
RigPoseResult EstimateRigPose(const std::vector<Correspondence>& correspondences,
                              const std::vector<Eigen::Isometry3d>& T_base_camera, const RigPoseOptions& options = {});

}  // namespace trimbot::visual_localization
