#pragma once
// The pre-built map visual localization runs against: keyframes of the ring (their poses in the
// map frame), 3D points with an Upright-SIFT descriptor each and their observations (tracks), and
// the retrieval vocabulary trained on the map's own descriptors. One versioned SQLite file per
// map; it records the garden and the camera rig it was made for, and loading checks both.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <vector>

#include "trimbot/robot/camera_rig.h"
#include "trimbot/visual_localization/features.h"

namespace trimbot::visual_localization {

// 2: the descriptor kind is recorded; 3: the builder and the garden's appearance version.
constexpr int kMapFormatVersion = 3;

struct MapKeyframe {
  int id = 0;
  double stamp = 0.0;
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
};

struct MapObservation {
  int keyframe = 0;                                 // keyframe id
  int camera = 0;                                   // ring camera index
  int point = 0;                                    // point id
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // distorted image coordinates
};

struct VisualMap {
  std::string garden;                                // the garden the map was made in
  std::string rig_signature;                         // RigSignature() of the calibration it was made with
  Descriptor descriptor = Descriptor::kUprightSift;  // of the points and the vocabulary
  std::string builder;                               // "log" or "surveyed" (KeyframePoses)
  // The version of the garden's appearance the mapping drive's images showed (the twin's texture
  // generator; 0 where it is not known): the harness refuses a map file of another version.
  int appearance_version = 0;
  std::vector<MapKeyframe> keyframes;
  std::vector<Eigen::Vector3d> points;  // map frame; id = index
  cv::Mat descriptors;                  // CV_32F, one row per point
  std::vector<MapObservation> observations;
  cv::Mat vocabulary;  // CV_32F, one row per visual word

  // Writes the map atomically. Throws std::runtime_error naming the file on failure.
  void Save(const std::string& path) const;
  // Reads a map; InputError naming the file when it is not a map, of another format version, or
  // made for another garden or camera rig (when those expectations are not empty) or with another
  // descriptor (when one is expected).
  static VisualMap Load(const std::string& path, const std::string& expected_garden = "",
                        const std::string& expected_rig_signature = "",
                        std::optional<Descriptor> expected_descriptor = std::nullopt);
};

// A short fingerprint of a rig's calibration (intrinsics, extrinsics at 0.1 mm / 0.01 px): a map
// made with one rig is refused by a stack with another.
std::string RigSignature(const robot::CameraRig& rig);

}  // namespace trimbot::visual_localization
