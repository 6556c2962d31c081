#pragma once
// Local image features for visual localization: Upright-SIFT, as on the real robot (reference
// deliverable D3.4, section 2.1.1). The ring's cameras stay upright on a mower base that drives
// on the ground, so the descriptor need not be rotation invariant, and dropping that invariance
// makes it more distinctive. How: OpenCV 4.6 SIFT detects keypoints (with an orientation each,
// duplicated where a point has several); every keypoint's angle is then set to 0 and duplicates
// merged before the descriptors are computed, and OpenCV's SIFT computes a descriptor in the
// keypoint's own orientation frame - so with angle 0 the descriptor grid stays aligned with the
// image axes and is not rotated.
#include <opencv2/core.hpp>

#include <vector>

namespace trimbot::visual_localization {

struct FeatureOptions {
  int max_features = 2000;   // strongest keypoints kept per image
  bool upright = true;       // false: ordinary (rotation-invariant) SIFT, for comparison
};

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // CV_32F, one 128-vector per keypoint
};

// Features of an 8-bit grayscale image. std::invalid_argument if it is not CV_8UC1.
Features ExtractFeatures(const cv::Mat& grey, const FeatureOptions& options = {});

}  // namespace trimbot::visual_localization
