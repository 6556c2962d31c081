#pragma once
// Visual localization of the ring against a pre-built map (reference deliverable D3.4, section
// 2.3): Upright-SIFT on the ring's images; retrieval of map keyframes by the vocabulary
// (tf-idf bag of words, cosine similarity), restricted to keyframes near the pose prior when
// there is one; 2D-3D matches with the points those keyframes observe (each feature against the
// points of its two nearest words, ratio test); the ring's
// pose from all cameras at once (GP3P + RANSAC + refinement) with a covariance from the inliers.
// Cameras missing from a frame are simply not used.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/visual_localization/features.h"
#include "trimbot/visual_localization/rig_pose.h"
#include "trimbot/visual_localization/visual_map.h"

namespace trimbot::visual_localization {

enum class Retrieval { kVocabulary, kPosePrior, kCombined };

struct LocalizerOptions {
  FeatureOptions features{1000, Descriptor::kUprightSift};
  Retrieval retrieval = Retrieval::kCombined;
  int keyframes = 20;         // top-k retrieved keyframes whose points are matched
  double prior_radius = 3.0;  // m: with a pose prior, only keyframes this close are candidates
  double ratio = 0.8;         // Lowe's ratio test
  RigPoseOptions pose;
  std::vector<int> cameras;                 // ring cameras used (empty: every camera in the frame)
  double min_position_sigma = 0.02;         // m: floor of the reported covariance
  double min_yaw_sigma = 0.5 * M_PI / 180;  // rad
};

struct LocalizationTimings {
  double features = 0.0, retrieval = 0.0, matching = 0.0, pose = 0.0;  // wall-clock seconds
};

// Where a frame that gave no pose failed.
enum class FailedStage { kNone, kFeatures, kRetrieval, kMatching, kPose };
const char* ToString(FailedStage stage);  // "", "features", "retrieval", "matching", "pose"

struct LocalizationResult {
  bool success = false;
  double stamp = 0.0;
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d planar_covariance = Eigen::Matrix3d::Identity();  // of (x, y, yaw)
  std::vector<int> retrieved;                                       // keyframe ids, best first
  int features = 0, matches = 0, inliers = 0;
  LocalizationTimings timings;
  std::string failure;  // why no pose, in words
  FailedStage failed_stage = FailedStage::kNone;
};

class VisualLocalizer {
 public:
  VisualLocalizer(VisualMap map, const robot::CameraRig& rig, const LocalizerOptions& options);

  // Features of a frame (per camera, bearings in the calibration's camera frames).
  struct FrameFeatures {
    std::vector<int> camera;                // per feature
    std::vector<Eigen::Vector3d> bearings;  // per feature
    cv::Mat descriptors;                    // all features, stacked
    std::vector<std::array<int, 2>> words;  // per feature: its two nearest visual words (AssignWords)
  };
  FrameFeatures Extract(const messages::RingFrame& frame) const;
  // The features' visual words (needed by Retrieve and Match).
  void AssignWords(FrameFeatures* features) const;
  // The best `count` keyframe ids by `method` for these features (and the prior's position, if
  // any), best first.
  std::vector<int> Retrieve(const FrameFeatures& features, const std::optional<Eigen::Vector2d>& prior_position,
                            Retrieval method, int count) const;
  // 2D-3D correspondences of the features with the points these keyframes observe: each feature
  // against the points of its two nearest words, ratio test.
  std::vector<Correspondence> Match(const FrameFeatures& features, const std::vector<int>& keyframes) const;
  // The whole pipeline: Extract, Retrieve (the options' method), Match, EstimateRigPose.
  LocalizationResult Localize(const messages::RingFrame& frame, const std::optional<Eigen::Vector2d>& prior_position);

  const VisualMap& map() const { return map_; }
  const LocalizerOptions& options() const { return options_; }
  // The ring cameras it uses (the options' list, or every camera of the rig).
  std::vector<int> cameras() const;
  const std::vector<Eigen::Isometry3d>& T_base_camera() const { return T_base_camera_; }

 private:
  cv::Mat WordHistogram(const FrameFeatures& features) const;

  VisualMap map_;
  robot::CameraRig rig_;
  LocalizerOptions options_;
  std::vector<Eigen::Isometry3d> T_base_camera_;
  std::vector<std::vector<int>> keyframe_points_;  // per keyframe id
  std::vector<int> point_words_;                   // per map point: its nearest visual word
  cv::Mat keyframe_histograms_;                    // one tf-idf row per keyframe, L2-normalized
  cv::Mat idf_;
};

}  // namespace trimbot::visual_localization
