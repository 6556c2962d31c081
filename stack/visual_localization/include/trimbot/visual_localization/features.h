#pragma once
// Local image features for visual localization: Upright-SIFT, as on the real robot (reference
// deliverable D3.4, section 2.1.1). The ring's cameras stay upright on a mower base that drives
// on the ground, so the descriptor need not be rotation invariant, and dropping that invariance
// makes it more distinctive. How: OpenCV 4.6 SIFT detects keypoints (with an orientation each,
// duplicated where a point has several); every keypoint's angle is then set to 0 and duplicates
// merged before the descriptors are computed, and OpenCV's SIFT computes a descriptor in the
// keypoint's own orientation frame - so with angle 0 the descriptor grid stays aligned with the
// image axes and is not rotated.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/camera_rig.h"

namespace trimbot::visual_localization {

// Which descriptor: Upright-SIFT (the robot's), or ordinary rotation-invariant SIFT (section
// 2.1.1's comparison). A map records its descriptor; a localizer refuses a map of the other kind.
enum class Descriptor { kUprightSift, kSift };
const char* ToString(Descriptor descriptor);
// "upright_sift" or "sift"; std::invalid_argument otherwise.
Descriptor DescriptorFromString(const std::string& name);

struct FeatureOptions {
  int max_features = 2000;  // strongest keypoints kept per image
  Descriptor descriptor = Descriptor::kUprightSift;
};

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // CV_32F, one 128-vector per keypoint
};

// Features of an 8-bit grayscale image. std::invalid_argument if it is not CV_8UC1.
Features ExtractFeatures(const cv::Mat& grey, const FeatureOptions& options = {});

// The features of one ring image with their rays, as mapping and localization use them.
struct ImageFeatures {
  std::vector<Eigen::Vector2d> pixels;    // in the calibration's resolution
  std::vector<Eigen::Vector3d> bearings;  // unit rays in the camera's optical frame
  cv::Mat descriptors;
};
// `camera`: the image's calibration; an image rendered at a fraction of it is scaled back.
ImageFeatures ExtractImageFeatures(const messages::Image& image, const robot::PinholeRadtan& camera,
                                   const FeatureOptions& options);

}  // namespace trimbot::visual_localization
