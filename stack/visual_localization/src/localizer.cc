#include "trimbot/visual_localization/localizer.h"

#include <opencv2/features2d.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <set>

namespace trimbot::visual_localization {
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

// Nearest visual word of a descriptor: a brute-force matcher over the vocabulary (a few hundred
// words: exact and fast enough).
struct VisualLocalizer::Index {
  cv::BFMatcher words{cv::NORM_L2};
};

VisualLocalizer::VisualLocalizer(VisualMap map, const robot::CameraRig& rig, const LocalizerOptions& options)
    : map_(std::move(map)), rig_(rig), options_(options), index_(std::make_unique<Index>()) {
  for (const auto& camera : rig_.cameras()) T_base_camera_.push_back(camera.T_base_camera);
  int max_id = -1;
  for (const auto& k : map_.keyframes) max_id = std::max(max_id, k.id);
  keyframe_points_.resize(static_cast<std::size_t>(max_id + 1));
  for (const auto& o : map_.observations) {
    if (o.keyframe >= 0 && o.keyframe <= max_id) keyframe_points_[static_cast<std::size_t>(o.keyframe)].push_back(o.point);
  }
  for (auto& points : keyframe_points_) {
    std::sort(points.begin(), points.end());
    points.erase(std::unique(points.begin(), points.end()), points.end());
  }
  if (map_.vocabulary.empty()) return;
  index_->words.add(map_.vocabulary);
  // tf-idf: a word seen by few keyframes says more about the place.
  const int words = map_.vocabulary.rows;
  cv::Mat raw(static_cast<int>(keyframe_points_.size()), words, CV_32F, cv::Scalar(0));
  std::vector<cv::DMatch> nearest;
  index_->words.match(map_.descriptors, nearest);
  for (std::size_t k = 0; k < keyframe_points_.size(); ++k) {
    for (int p : keyframe_points_[k]) raw.at<float>(static_cast<int>(k), nearest[static_cast<std::size_t>(p)].trainIdx) += 1.0f;
  }
  idf_ = cv::Mat(1, words, CV_32F);
  for (int w = 0; w < words; ++w) {
    const int seen = cv::countNonZero(raw.col(w));
    idf_.at<float>(0, w) = static_cast<float>(std::log((raw.rows + 1.0) / (seen + 1.0)));
  }
  keyframe_histograms_ = raw.clone();
  for (int k = 0; k < raw.rows; ++k) {
    cv::Mat row = keyframe_histograms_.row(k);
    row = row.mul(idf_);
    const double norm = cv::norm(row);
    if (norm > 0) row /= norm;
  }
}

VisualLocalizer::~VisualLocalizer() = default;

cv::Mat VisualLocalizer::WordHistogram(const cv::Mat& descriptors) const {
  cv::Mat histogram(1, map_.vocabulary.rows, CV_32F, cv::Scalar(0));
  if (descriptors.empty() || map_.vocabulary.empty()) return histogram;
  std::vector<cv::DMatch> nearest;
  index_->words.match(descriptors, nearest);
  for (const auto& m : nearest) histogram.at<float>(0, m.trainIdx) += 1.0f;
  histogram = histogram.mul(idf_);
  const double norm = cv::norm(histogram);
  if (norm > 0) histogram /= norm;
  return histogram;
}

VisualLocalizer::FrameFeatures VisualLocalizer::Extract(const messages::RingFrame& frame) const {
  FrameFeatures out;
  std::vector<cv::Mat> descriptors;
  for (const auto& image : frame.images) {
    if (image.camera_index < 0 || image.camera_index >= rig_.size() || image.data.empty()) continue;
    if (!options_.cameras.empty() &&
        std::find(options_.cameras.begin(), options_.cameras.end(), image.camera_index) == options_.cameras.end()) {
      continue;
    }
    const ImageFeatures f = ExtractImageFeatures(image, rig_.camera(image.camera_index).intrinsics, options_.features);
    out.camera.insert(out.camera.end(), f.bearings.size(), image.camera_index);
    out.bearings.insert(out.bearings.end(), f.bearings.begin(), f.bearings.end());
    if (!f.descriptors.empty()) descriptors.push_back(f.descriptors);
  }
  if (!descriptors.empty()) cv::vconcat(descriptors, out.descriptors);
  return out;
}

std::vector<int> VisualLocalizer::Retrieve(const FrameFeatures& features,
                                           const std::optional<Eigen::Vector2d>& prior_position) const {
  const bool use_prior = prior_position && options_.retrieval != Retrieval::kVocabulary;
  const bool use_words = options_.retrieval != Retrieval::kPosePrior || !prior_position;
  const cv::Mat query = use_words ? WordHistogram(features.descriptors) : cv::Mat();
  std::vector<std::pair<double, int>> ranked;  // (score, keyframe id); higher is better
  for (const auto& k : map_.keyframes) {
    const double distance = prior_position ? (k.T_map_base.translation().head<2>() - *prior_position).norm() : 0.0;
    if (use_prior && distance > options_.prior_radius) continue;
    const double similarity = use_words && !keyframe_histograms_.empty() ? query.dot(keyframe_histograms_.row(k.id)) : 0.0;
    ranked.push_back({use_words ? similarity : -distance, k.id});
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<int> ids;
  for (std::size_t i = 0; i < ranked.size() && static_cast<int>(i) < options_.keyframes; ++i) ids.push_back(ranked[i].second);
  return ids;
}

LocalizationResult VisualLocalizer::Localize(const messages::RingFrame& frame,
                                             const std::optional<Eigen::Vector2d>& prior_position) {
  LocalizationResult result;
  result.stamp = frame.stamp;
  auto start = Clock::now();
  const FrameFeatures features = Extract(frame);
  result.features = features.descriptors.rows;
  result.timings.features = Since(start);
  start = Clock::now();
  result.retrieved = Retrieve(features, prior_position);
  result.timings.retrieval = Since(start);
  if (features.descriptors.rows < options_.pose.min_inliers || result.retrieved.empty()) {
    result.failure = features.descriptors.rows < options_.pose.min_inliers ? "too few features" : "no keyframe retrieved";
    return result;
  }
  start = Clock::now();
  std::set<int> candidate_set;
  for (int id : result.retrieved) candidate_set.insert(keyframe_points_[static_cast<std::size_t>(id)].begin(),
                                                       keyframe_points_[static_cast<std::size_t>(id)].end());
  const std::vector<int> candidates(candidate_set.begin(), candidate_set.end());
  std::vector<Correspondence> correspondences;
  if (candidates.size() >= 2) {
    cv::Mat points(static_cast<int>(candidates.size()), map_.descriptors.cols, CV_32F);
    for (std::size_t i = 0; i < candidates.size(); ++i) map_.descriptors.row(candidates[i]).copyTo(points.row(static_cast<int>(i)));
    cv::BFMatcher matcher(cv::NORM_L2);
    std::vector<std::vector<cv::DMatch>> knn;
    matcher.knnMatch(features.descriptors, points, knn, 2);
    for (const auto& pair : knn) {
      if (pair.size() < 2 || pair[0].distance > options_.ratio * pair[1].distance) continue;
      const std::size_t q = static_cast<std::size_t>(pair[0].queryIdx);
      correspondences.push_back({features.camera[q], features.bearings[q],
                                 map_.points[static_cast<std::size_t>(candidates[static_cast<std::size_t>(pair[0].trainIdx)])]});
    }
  }
  result.matches = static_cast<int>(correspondences.size());
  result.timings.matching = Since(start);
  start = Clock::now();
  const RigPoseResult pose = EstimateRigPose(correspondences, T_base_camera_, options_.pose);
  result.timings.pose = Since(start);
  if (!pose.success) {
    result.failure = pose.failure;
    return result;
  }
  result.success = true;
  result.T_map_base = pose.T_map_base;
  result.inliers = static_cast<int>(pose.inliers.size());
  // Planar covariance: position from the translation block, yaw from the rotation about z.
  Eigen::Matrix3d c;
  c << pose.covariance(3, 3), pose.covariance(3, 4), pose.covariance(3, 2), pose.covariance(4, 3), pose.covariance(4, 4),
      pose.covariance(4, 2), pose.covariance(2, 3), pose.covariance(2, 4), pose.covariance(2, 2);
  c(0, 0) += options_.min_position_sigma * options_.min_position_sigma;
  c(1, 1) += options_.min_position_sigma * options_.min_position_sigma;
  c(2, 2) += options_.min_yaw_sigma * options_.min_yaw_sigma;
  result.planar_covariance = c;
  return result;
}

}  // namespace trimbot::visual_localization
