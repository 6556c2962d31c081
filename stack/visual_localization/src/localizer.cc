#include "trimbot/visual_localization/localizer.h"

#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>
#include <stdexcept>

#include "trimbot/common/wall_clock.h"

namespace trimbot::visual_localization {
namespace {

using Clock = std::chrono::steady_clock;

// The two nearest visual words of each descriptor: brute force over the vocabulary (a few hundred
// words: exact and fast enough), blocks of rows in parallel, each into its own slots - the same
// words for any number of threads.
std::vector<std::array<int, 2>> TwoNearestWords(const cv::Mat& descriptors, const cv::Mat& vocabulary) {
  const int rows = descriptors.rows;
  std::vector<std::array<int, 2>> words(static_cast<std::size_t>(rows));
  constexpr int kBlock = 256;
  cv::parallel_for_(cv::Range(0, (rows + kBlock - 1) / kBlock), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b) {
      const int begin = b * kBlock, end = std::min(rows, begin + kBlock);
      std::vector<std::vector<cv::DMatch>> nearest;
      cv::BFMatcher(cv::NORM_L2).knnMatch(descriptors.rowRange(begin, end), vocabulary, nearest, 2);
      for (int i = begin; i < end; ++i) {
        const auto& pair = nearest[static_cast<std::size_t>(i - begin)];
        words[static_cast<std::size_t>(i)] = {pair.at(0).trainIdx,
                                              pair.size() > 1 ? pair[1].trainIdx : pair[0].trainIdx};
      }
    }
  });
  return words;
}

}  // namespace

VisualLocalizer::VisualLocalizer(VisualMap map, const robot::CameraRig& rig, const LocalizerOptions& options)
    : map_(std::move(map)), rig_(rig), options_(options) {
  for (const auto& camera : rig_.cameras()) T_base_camera_.push_back(camera.T_base_camera);
  int max_id = -1;
  for (const auto& k : map_.keyframes) max_id = std::max(max_id, k.id);
  keyframe_points_.resize(static_cast<std::size_t>(max_id + 1));
  for (const auto& o : map_.observations) {
    if (o.keyframe >= 0 && o.keyframe <= max_id)
      keyframe_points_[static_cast<std::size_t>(o.keyframe)].push_back(o.point);
  }
  for (auto& points : keyframe_points_) {
    std::sort(points.begin(), points.end());
    points.erase(std::unique(points.begin(), points.end()), points.end());
  }
  if (map_.vocabulary.empty()) return;
  // tf-idf: a word seen by few keyframes says more about the place.
  const int words = map_.vocabulary.rows;
  cv::Mat raw(static_cast<int>(keyframe_points_.size()), words, CV_32F, cv::Scalar(0));
  for (const auto& nearest : TwoNearestWords(map_.descriptors, map_.vocabulary)) point_words_.push_back(nearest[0]);
  for (std::size_t k = 0; k < keyframe_points_.size(); ++k) {
    for (int p : keyframe_points_[k])
      raw.at<float>(static_cast<int>(k), point_words_[static_cast<std::size_t>(p)]) += 1.0f;
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

cv::Mat VisualLocalizer::WordHistogram(const FrameFeatures& features) const {
  if (map_.vocabulary.empty()) return cv::Mat();  // no words: retrieval by position alone
  cv::Mat histogram(1, map_.vocabulary.rows, CV_32F, cv::Scalar(0));
  for (const auto& words : features.words) histogram.at<float>(0, words[0]) += 1.0f;
  histogram = histogram.mul(idf_);
  const double norm = cv::norm(histogram);
  if (norm > 0) histogram /= norm;
  return histogram;
}

VisualLocalizer::FrameFeatures VisualLocalizer::Extract(const messages::RingFrame& frame) const {
  std::vector<const messages::Image*> images;
  for (const auto& image : frame.images) {
    if (image.camera_index < 0 || image.camera_index >= rig_.size() || image.data.empty()) continue;
    if (!options_.cameras.empty() &&
        std::find(options_.cameras.begin(), options_.cameras.end(), image.camera_index) == options_.cameras.end()) {
      continue;
    }
    images.push_back(&image);
  }
  // The cameras' images are independent: extracted in parallel, each into its own slot, so the
  // result does not depend on the number of threads.
  std::vector<ImageFeatures> per_image(images.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(images.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const messages::Image& image = *images[static_cast<std::size_t>(i)];
      per_image[static_cast<std::size_t>(i)] =
          ExtractImageFeatures(image, rig_.camera(image.camera_index).intrinsics, options_.features);
    }
  });
  FrameFeatures out;
  std::vector<cv::Mat> descriptors;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const ImageFeatures& f = per_image[i];
    out.camera.insert(out.camera.end(), f.bearings.size(), images[i]->camera_index);
    out.bearings.insert(out.bearings.end(), f.bearings.begin(), f.bearings.end());
    if (!f.descriptors.empty()) descriptors.push_back(f.descriptors);
  }
  if (!descriptors.empty()) cv::vconcat(descriptors, out.descriptors);
  return out;
}

void VisualLocalizer::AssignWords(FrameFeatures* features) const {
  features->words.clear();
  if (map_.vocabulary.empty()) {  // a map without points: one empty word
    features->words.assign(static_cast<std::size_t>(features->descriptors.rows), {0, 0});
    return;
  }
  features->words = TwoNearestWords(features->descriptors, map_.vocabulary);
}

std::vector<int> VisualLocalizer::Retrieve(const FrameFeatures& features,
                                           const std::optional<Eigen::Vector2d>& prior_position, Retrieval method,
                                           int count) const {
  const bool use_prior = prior_position && method != Retrieval::kVocabulary;
  const bool use_words = method != Retrieval::kPosePrior || !prior_position;
  const cv::Mat query = use_words ? WordHistogram(features) : cv::Mat();
  std::vector<std::pair<double, int>> ranked;  // (score, keyframe id); higher is better
  for (const auto& k : map_.keyframes) {
    const double distance = prior_position ? (k.T_map_base.translation().head<2>() - *prior_position).norm() : 0.0;
    if (use_prior && distance > options_.prior_radius) continue;
    const double similarity =
        use_words && !keyframe_histograms_.empty() ? query.dot(keyframe_histograms_.row(k.id)) : 0.0;
    ranked.push_back({use_words ? similarity : -distance, k.id});
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<int> ids;
  for (std::size_t i = 0; i < ranked.size() && static_cast<int>(i) < count; ++i) ids.push_back(ranked[i].second);
  return ids;
}

std::vector<Correspondence> VisualLocalizer::Match(const FrameFeatures& features,
                                                   const std::vector<int>& keyframes) const {
  // The keyframes' points, by visual word: a query descriptor is compared with the points of its
  // two nearest words only (as a vocabulary tree's direct index), not with every candidate.
  std::vector<std::vector<int>> by_word(static_cast<std::size_t>(std::max(1, map_.vocabulary.rows)));
  std::set<int> seen;
  for (int id : keyframes) {
    for (int p : keyframe_points_[static_cast<std::size_t>(id)]) {
      if (seen.insert(p).second)
        by_word[static_cast<std::size_t>(point_words_[static_cast<std::size_t>(p)])].push_back(p);
    }
  }
  const int n = features.descriptors.rows;
  if (static_cast<int>(features.words.size()) != n) {
    throw std::logic_error("VisualLocalizer::Match: the features' words are not assigned (call AssignWords)");
  }
  const int width = map_.descriptors.cols;
  std::vector<int> best(static_cast<std::size_t>(n), -1);  // matched point per query, -1: none
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& range) {
    for (int q = range.start; q < range.end; ++q) {
      const float* query = features.descriptors.ptr<float>(q);
      float first = std::numeric_limits<float>::max(), second = first;
      int first_point = -1;
      const auto& words = features.words[static_cast<std::size_t>(q)];
      for (int w = 0; w < 2; ++w) {
        if (w == 1 && words[1] == words[0]) break;
        for (int p : by_word[static_cast<std::size_t>(words[static_cast<std::size_t>(w)])]) {
          const float d = cv::normL2Sqr<float, float>(query, map_.descriptors.ptr<float>(p), width);
          if (d < first) {
            second = first;
            first = d;
            first_point = p;
          } else if (d < second) {
            second = d;
          }
        }
      }
      // Lowe's ratio test on distances (squared here); a lone candidate cannot pass it.
      if (first_point >= 0 && second < std::numeric_limits<float>::max() &&
          first <= options_.ratio * options_.ratio * second) {
        best[static_cast<std::size_t>(q)] = first_point;
      }
    }
  });
  std::vector<Correspondence> correspondences;
  for (int q = 0; q < n; ++q) {
    const int p = best[static_cast<std::size_t>(q)];
    if (p >= 0)
      correspondences.push_back({features.camera[static_cast<std::size_t>(q)],
                                 features.bearings[static_cast<std::size_t>(q)],
                                 map_.points[static_cast<std::size_t>(p)]});
  }
  return correspondences;
}

std::vector<int> VisualLocalizer::cameras() const {
  if (!options_.cameras.empty()) return options_.cameras;
  std::vector<int> all(T_base_camera_.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  return all;
}

const char* ToString(FailedStage stage) {
  switch (stage) {
    case FailedStage::kNone:
      return "";
    case FailedStage::kFeatures:
      return "features";
    case FailedStage::kRetrieval:
      return "retrieval";
    case FailedStage::kMatching:
      return "matching";
    case FailedStage::kPose:
      return "pose";
  }
  return "";
}

LocalizationResult VisualLocalizer::Localize(const messages::RingFrame& frame,
                                             const std::optional<Eigen::Vector2d>& prior_position) {
  LocalizationResult result;
  result.stamp = frame.stamp;
  auto start = Clock::now();
  FrameFeatures features = Extract(frame);
  result.features = features.descriptors.rows;
  result.timings.features = SecondsSince(start);
  start = Clock::now();
  AssignWords(&features);
  result.retrieved = Retrieve(features, prior_position, options_.retrieval, options_.keyframes);
  result.timings.retrieval = SecondsSince(start);
  if (features.descriptors.rows < options_.pose.min_inliers || result.retrieved.empty()) {
    const bool few_features = features.descriptors.rows < options_.pose.min_inliers;
    result.failure = few_features ? "too few features" : "no keyframe retrieved";
    result.failed_stage = few_features ? FailedStage::kFeatures : FailedStage::kRetrieval;
    return result;
  }
  start = Clock::now();
  const std::vector<Correspondence> correspondences = Match(features, result.retrieved);
  result.matches = static_cast<int>(correspondences.size());
  result.timings.matching = SecondsSince(start);
  start = Clock::now();
  const RigPoseResult pose = EstimateRigPose(correspondences, T_base_camera_, options_.pose);
  result.timings.pose = SecondsSince(start);
  if (!pose.success) {
    result.failure = pose.failure;
    result.failed_stage =
        result.matches < std::max(options_.pose.min_inliers, 3) ? FailedStage::kMatching : FailedStage::kPose;
    return result;
  }
  result.success = true;
  result.T_map_base = pose.T_map_base;
  result.inliers = static_cast<int>(pose.inliers.size());
  // Planar covariance: position from the translation block, yaw from the rotation about z.
  Eigen::Matrix3d c;
  c << pose.covariance(3, 3), pose.covariance(3, 4), pose.covariance(3, 2), pose.covariance(4, 3),
      pose.covariance(4, 4), pose.covariance(4, 2), pose.covariance(2, 3), pose.covariance(2, 4), pose.covariance(2, 2);
  c(0, 0) += options_.min_position_sigma * options_.min_position_sigma;
  c(1, 1) += options_.min_position_sigma * options_.min_position_sigma;
  c(2, 2) += options_.min_yaw_sigma * options_.min_yaw_sigma;
  result.planar_covariance = c;
  return result;
}

}  // namespace trimbot::visual_localization
