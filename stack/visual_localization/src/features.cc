#include "trimbot/visual_localization/features.h"

#include <opencv2/features2d.hpp>

#include <algorithm>
#include <stdexcept>

namespace trimbot::visual_localization {

Features ExtractFeatures(const cv::Mat& grey, const FeatureOptions& options) {
  if (grey.empty() || grey.type() != CV_8UC1) throw std::invalid_argument("ExtractFeatures: expects an 8-bit grey image");
  const cv::Ptr<cv::SIFT> sift = cv::SIFT::create(options.max_features);
  Features f;
  if (!options.upright) {
    sift->detectAndCompute(grey, cv::noArray(), f.keypoints, f.descriptors);
    return f;
  }
  std::vector<cv::KeyPoint> detected;
  sift->detect(grey, detected);
  // One upright keypoint per location and scale (SIFT duplicates points with several orientations).
  for (auto& k : detected) k.angle = 0.0f;
  std::sort(detected.begin(), detected.end(), [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
    if (a.pt.x != b.pt.x) return a.pt.x < b.pt.x;
    if (a.pt.y != b.pt.y) return a.pt.y < b.pt.y;
    return a.size < b.size;
  });
  detected.erase(std::unique(detected.begin(), detected.end(),
                             [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
                               return a.pt == b.pt && a.size == b.size && a.octave == b.octave;
                             }),
                 detected.end());
  f.keypoints = std::move(detected);
  sift->compute(grey, f.keypoints, f.descriptors);
  return f;
}

}  // namespace trimbot::visual_localization
