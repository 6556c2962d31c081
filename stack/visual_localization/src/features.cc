#include "trimbot/visual_localization/features.h"

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <stdexcept>

namespace trimbot::visual_localization {

const char* ToString(Descriptor descriptor) { return descriptor == Descriptor::kUprightSift ? "upright_sift" : "sift"; }

Descriptor DescriptorFromString(const std::string& name) {
  if (name == "upright_sift") return Descriptor::kUprightSift;
  if (name == "sift") return Descriptor::kSift;
  throw std::invalid_argument("unknown descriptor '" + name + "' (upright_sift, sift)");
}

Features ExtractFeatures(const cv::Mat& grey, const FeatureOptions& options) {
  if (grey.empty() || grey.type() != CV_8UC1)
    throw std::invalid_argument("ExtractFeatures: expects an 8-bit grey image");
  const cv::Ptr<cv::SIFT> sift = cv::SIFT::create(options.max_features);
  Features f;
  if (options.descriptor == Descriptor::kSift) {
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

ImageFeatures ExtractImageFeatures(const messages::Image& image, const robot::PinholeRadtan& camera,
                                   const FeatureOptions& options) {
  const cv::Mat raw(image.height, image.width, image.encoding == "mono8" ? CV_8UC1 : CV_8UC3,
                    const_cast<std::uint8_t*>(image.data.data()));
  cv::Mat grey = raw;
  if (raw.channels() == 3) cv::cvtColor(raw, grey, cv::COLOR_RGB2GRAY);
  const Features features = ExtractFeatures(grey, options);
  const double scale = static_cast<double>(image.width) / camera.width;  // rendered at a fraction
  ImageFeatures out;
  out.descriptors = features.descriptors;
  for (const auto& k : features.keypoints) {
    const Eigen::Vector2d pixel((k.pt.x + 0.5) / scale - 0.5, (k.pt.y + 0.5) / scale - 0.5);
    const Eigen::Vector2d normalized = camera.Undistort(pixel);
    out.pixels.push_back(pixel);
    out.bearings.push_back(Eigen::Vector3d(normalized.x(), normalized.y(), 1.0).normalized());
  }
  return out;
}

}  // namespace trimbot::visual_localization
