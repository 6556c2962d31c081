#include "trimbot/visual_localization/map_builder.h"

#include <opencv2/features2d.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <numeric>
#include <optional>

#include "map_adjustment.h"
#include "trimbot/common/rotation.h"
#include "trimbot/common/wall_clock.h"
#include "trimbot/visual_localization/localizer.h"

namespace trimbot::visual_localization {
namespace {

using mapping::Adjust;
using mapping::FeatureRef;
using mapping::MakeWheelScales;
using mapping::OptimizePoseGraph;
using mapping::PointTrack;
using mapping::TieToShapes;
using mapping::Track;
using mapping::WheelScales;

using Clock = std::chrono::steady_clock;

double RotationAngle(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  std::size_t Find(std::size_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Join(std::size_t a, std::size_t b) {
    a = Find(a), b = Find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);  // the smaller root: deterministic
  }

 private:
  std::vector<std::size_t> parent_;
};

// ---- matching ----------------------------------------------------------------------------------

struct ImageMatch {
  FeatureRef a, b;
};

Eigen::Isometry3d CameraPose(const std::vector<MappingKeyframe>& keyframes, const robot::CameraRig& rig, int k, int c) {
  return keyframes[static_cast<std::size_t>(k)].T_map_base * rig.camera(c).T_base_camera;
}

// How far (rad) the ray of b lies from the epipolar plane through both camera centres and the ray
// of a, at the keyframes' present poses.
double EpipolarAngle(const std::vector<MappingKeyframe>& keyframes, const robot::CameraRig& rig, const ImageMatch& m) {
  const Eigen::Isometry3d Ta = CameraPose(keyframes, rig, m.a.keyframe, m.a.camera);
  const Eigen::Isometry3d Tb = CameraPose(keyframes, rig, m.b.keyframe, m.b.camera);
  const Eigen::Vector3d ra = Ta.linear() * keyframes[m.a.keyframe].images[m.a.camera].bearings[m.a.feature];
  const Eigen::Vector3d rb = Tb.linear() * keyframes[m.b.keyframe].images[m.b.camera].bearings[m.b.feature];
  const Eigen::Vector3d normal = (Tb.translation() - Ta.translation()).cross(ra);
  if (normal.norm() < 1e-12) return M_PI;
  return std::abs(std::asin(std::clamp(normal.normalized().dot(rb), -1.0, 1.0)));
}

// Matches of image (ka, ca) with image (kb, cb): ratio test, then the epipolar angle (the rays
// must lie near the plane through both camera centres). Image pairs closer than `min_baseline`
// are skipped (no parallax), except the two cameras of a stereo pair, whose baseline is calibrated.
void MatchImages(const std::vector<MappingKeyframe>& keyframes, const robot::CameraRig& rig, int ka, int ca, int kb,
                 int cb, double ratio, double epipolar_angle, double min_baseline, std::vector<ImageMatch>* matches) {
  const MappingImage& A = keyframes[ka].images[ca];
  const MappingImage& B = keyframes[kb].images[cb];
  if (A.descriptors.rows < 2 || B.descriptors.rows < 2) return;
  const double baseline =
      (CameraPose(keyframes, rig, kb, cb).translation() - CameraPose(keyframes, rig, ka, ca).translation()).norm();
  if (baseline < min_baseline) return;
  cv::FlannBasedMatcher matcher(cv::makePtr<cv::flann::KDTreeIndexParams>(4), cv::makePtr<cv::flann::SearchParams>(32));
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(A.descriptors, B.descriptors, knn, 2);
  for (const auto& pair : knn) {
    if (pair.size() < 2 || pair[0].distance > ratio * pair[1].distance) continue;
    const ImageMatch m{{ka, ca, pair[0].queryIdx}, {kb, cb, pair[0].trainIdx}};
    if (EpipolarAngle(keyframes, rig, m) <= epipolar_angle) matches->push_back(m);
  }
}

// Every image pair of two keyframes whose optical axes are within `max_camera_angle`.
void MatchKeyframePair(const std::vector<MappingKeyframe>& keyframes, const robot::CameraRig& rig, int ka, int kb,
                       double epipolar_angle, const MapBuilderOptions& options, MapBuildStats* stats,
                       std::vector<ImageMatch>* matches) {
  for (int ca = 0; ca < rig.size(); ++ca) {
    for (int cb = 0; cb < rig.size(); ++cb) {
      const Eigen::Vector3d axis_a = CameraPose(keyframes, rig, ka, ca).linear().col(2);
      const Eigen::Vector3d axis_b = CameraPose(keyframes, rig, kb, cb).linear().col(2);
      if (std::acos(std::clamp(axis_a.dot(axis_b), -1.0, 1.0)) > options.max_camera_angle) continue;
      MatchImages(keyframes, rig, ka, ca, kb, cb, options.ratio, epipolar_angle, 0.05, matches);
      ++stats->images_matched;
    }
  }
}

// Each keyframe with the next few (and, from the odometry, the two cameras of each stereo pair
// within it).
std::vector<ImageMatch> MatchKeyframes(const std::vector<MappingKeyframe>& keyframes, const robot::CameraRig& rig,
                                       double epipolar_angle, const MapBuilderOptions& options, MapBuildStats* stats) {
  std::srand(1);  // FLANN's randomized trees draw from rand(): the same map from the same drive
  std::vector<ImageMatch> matches;
  const int n = static_cast<int>(keyframes.size());
  for (int ka = 0; ka < n; ++ka) {
    if (options.poses == KeyframePoses::kOdometry) {
      for (const auto& pair : rig.StereoPairs()) {
        const std::size_t before = matches.size();
        MatchImages(keyframes, rig, ka, pair.left, ka, pair.right, options.ratio, options.epipolar_angle, 0.0,
                    &matches);
        stats->stereo_matches += static_cast<int>(matches.size() - before);
        ++stats->images_matched;
      }
    }
    for (int kb = ka + 1; kb < n && kb <= ka + options.match_next_keyframes; ++kb) {
      MatchKeyframePair(keyframes, rig, ka, kb, epipolar_angle, options, stats, &matches);
    }
  }
  return matches;
}

// ---- tracks and points -------------------------------------------------------------------------

std::vector<Track> JoinTracks(const std::vector<MappingKeyframe>& keyframes, const std::vector<ImageMatch>& matches) {
  // A global index for every feature of every image.
  std::vector<std::vector<std::size_t>> offset(keyframes.size());
  std::vector<FeatureRef> refs;
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    for (std::size_t c = 0; c < keyframes[k].images.size(); ++c) {
      offset[k].push_back(refs.size());
      for (std::size_t f = 0; f < keyframes[k].images[c].bearings.size(); ++f) {
        refs.push_back({static_cast<int>(k), static_cast<int>(c), static_cast<int>(f)});
      }
    }
  }
  const auto index = [&](const FeatureRef& r) {
    return offset[r.keyframe][r.camera] + static_cast<std::size_t>(r.feature);
  };
  UnionFind sets(refs.size());
  for (const auto& m : matches) sets.Join(index(m.a), index(m.b));
  std::map<std::size_t, Track> by_root;
  for (const auto& m : matches) {
    for (const FeatureRef& r : {m.a, m.b}) by_root[sets.Find(index(r))];
  }
  for (std::size_t i = 0; i < refs.size(); ++i) {
    const auto it = by_root.find(sets.Find(i));
    if (it != by_root.end()) it->second.push_back(refs[i]);
  }
  std::vector<Track> tracks;
  for (auto& [root, track] : by_root) {
    // One feature per image, or the track joined two different points.
    std::map<std::pair<int, int>, int> images;
    bool consistent = true;
    for (const auto& r : track) consistent = consistent && ++images[{r.keyframe, r.camera}] == 1;
    if (consistent && track.size() >= 2) tracks.push_back(std::move(track));
  }
  return tracks;
}

// Whether a track holds observations from at least two keyframes. A track seen by one keyframe
// only (the two cameras of a stereo pair) is not a map point: its depth rests on a 3 cm baseline
// (at 1.5 m and 1 px, 10-15 cm along the ray), no second pose checks it, and it constrains no
// keyframe pose in the adjustment. The next keyframe's stereo pair sees the same surface again as
// another such track, so a surface passed twice or slowly became many near-copies of one point -
// which defeat the localizer's ratio test (its best and second-best candidates are one surface).
// Stereo observations still join tracks that span keyframes, and give the map its scale there.
bool SpansKeyframes(const Track& track) {
  for (const auto& r : track) {
    if (r.keyframe != track.front().keyframe) return true;
  }
  return false;
}

// Midpoint triangulation from the keyframes' present poses; nullopt when the rays do not make a
// good point (too parallel, behind or too far, or a ray further than `max_ray_angle` off it).
std::optional<Eigen::Vector3d> Triangulate(const std::vector<MappingKeyframe>& keyframes, const robot::CameraRig& rig,
                                           const Track& track, const MapBuilderOptions& options, double max_ray_angle) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> rays;
  std::vector<Eigen::Isometry3d> cameras;
  for (const auto& r : track) {
    const Eigen::Isometry3d T = keyframes[r.keyframe].T_map_base * rig.camera(r.camera).T_base_camera;
    const Eigen::Vector3d d = T.linear() * keyframes[r.keyframe].images[r.camera].bearings[r.feature];
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * T.translation();
    rays.push_back(d);
    cameras.push_back(T);
  }
  double widest = 0.0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    for (std::size_t j = i + 1; j < rays.size(); ++j)
      widest = std::max(widest, std::acos(std::clamp(rays[i].dot(rays[j]), -1.0, 1.0)));
  }
  if (widest < options.min_triangulation_angle || std::abs(A.determinant()) < 1e-12) return std::nullopt;
  const Eigen::Vector3d X = A.ldlt().solve(b);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Eigen::Vector3d in_camera = cameras[i].inverse() * X;
    if (in_camera.z() < 0.2 || in_camera.norm() > options.max_depth) return std::nullopt;
    if (std::acos(std::clamp(in_camera.normalized().dot(cameras[i].linear().transpose() * rays[i]), -1.0, 1.0)) >
        max_ray_angle) {
      return std::nullopt;
    }
  }
  return X;
}

// Drops observations with an error above `max_error` (px; `errors` as Adjust gives them), then
// points no longer seen from two keyframes. Returns how many observations were dropped.
int RemoveOutliers(const std::vector<double>& errors, double max_error, std::vector<PointTrack>& points) {
  std::size_t next = 0;
  int dropped = 0;
  std::vector<PointTrack> kept;
  for (auto& p : points) {
    Track track;
    for (const auto& r : p.track) {
      if (errors[next++] <= max_error) track.push_back(r);
    }
    dropped += static_cast<int>(p.track.size() - track.size());
    if (SpansKeyframes(track)) kept.push_back({p.position, std::move(track)});
  }
  points = std::move(kept);
  return dropped;
}

// The retrieval vocabulary: k-means over the map's descriptors (seeded: the same map, the same words).
cv::Mat TrainVocabulary(const cv::Mat& descriptors, int words) {
  if (descriptors.rows <= words) return descriptors.clone();
  cv::setRNGSeed(1);
  cv::Mat labels, centres;
  cv::kmeans(descriptors, words, labels, cv::TermCriteria(cv::TermCriteria::MAX_ITER + cv::TermCriteria::EPS, 15, 1e-3),
             1, cv::KMEANS_PP_CENTERS, centres);
  return centres;
}

std::vector<PointTrack> TriangulateTracks(const std::vector<MappingKeyframe>& keyframes, const robot::CameraRig& rig,
                                          const std::vector<ImageMatch>& matches, const MapBuilderOptions& options,
                                          double max_ray_angle, MapBuildStats* stats) {
  const std::vector<Track> tracks = JoinTracks(keyframes, matches);
  stats->tracks = static_cast<int>(tracks.size());
  stats->single_keyframe_tracks = 0;
  stats->matches = static_cast<int>(matches.size());
  std::vector<PointTrack> points;
  for (const auto& track : tracks) {
    if (!SpansKeyframes(track)) {
      ++stats->single_keyframe_tracks;
      continue;
    }
    if (const auto X = Triangulate(keyframes, rig, track, options, max_ray_angle)) points.push_back({*X, track});
  }
  return points;
}

// Adjust, drop the observations the adjusted map cannot explain (wrong matches, silhouettes that
// move with the viewpoint), adjust again.
void AdjustTwice(const robot::CameraRig& rig, const MapBuilderOptions& options, std::vector<MappingKeyframe>& keyframes,
                 std::vector<PointTrack>& points, WheelScales& scales, MapBuildStats* stats) {
  std::vector<double> errors;
  Adjust(rig, options, keyframes, points, scales, &errors);
  stats->outlier_observations = RemoveOutliers(errors, options.max_reprojection_error, points);
  stats->reprojection_rmse_px = Adjust(rig, options, keyframes, points, scales, &errors);
}

// The map of these keyframes and points (each point's descriptor the mean of its track's).
VisualMap MakeMap(const std::string& garden, const robot::CameraRig& rig, const MapBuilderOptions& options,
                  const std::vector<MappingKeyframe>& keyframes, const std::vector<PointTrack>& points) {
  VisualMap map;
  map.garden = garden;
  map.rig_signature = RigSignature(rig);
  map.descriptor = options.features.descriptor;
  map.builder = ToString(options.poses);
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    map.keyframes.push_back({static_cast<int>(k), keyframes[k].stamp, keyframes[k].T_map_base});
  }
  std::vector<cv::Mat> descriptors;
  for (std::size_t i = 0; i < points.size(); ++i) {
    cv::Mat mean = cv::Mat::zeros(1, 128, CV_32F);
    for (const auto& r : points[i].track) {
      const MappingImage& image = keyframes[r.keyframe].images[r.camera];
      mean += image.descriptors.row(r.feature);
      map.observations.push_back({r.keyframe, r.camera, static_cast<int>(i), image.pixels[r.feature]});
    }
    descriptors.push_back(mean / static_cast<double>(points[i].track.size()));
    map.points.push_back(points[i].position);
  }
  if (!descriptors.empty()) cv::vconcat(descriptors, map.descriptors);
  if (!map.descriptors.empty()) map.vocabulary = TrainVocabulary(map.descriptors, options.vocabulary_words);
  return map;
}

// The keyframe steps k-1 -> k whose keyframes share fewer than `min_shared` points.
std::vector<int> FindGaps(std::size_t keyframes, const std::vector<PointTrack>& points, int min_shared) {
  std::vector<int> shared(keyframes, 0);
  for (const auto& p : points) {
    std::vector<bool> seen(keyframes, false);
    for (const auto& r : p.track) seen[static_cast<std::size_t>(r.keyframe)] = true;
    for (std::size_t k = 1; k < keyframes; ++k) shared[k] += seen[k - 1] && seen[k] ? 1 : 0;
  }
  std::vector<int> gaps;
  for (std::size_t k = 1; k < keyframes; ++k) {
    if (shared[k] < min_shared) gaps.push_back(static_cast<int>(k));
  }
  return gaps;
}

// Odometry distance travelled up to each keyframe.
std::vector<double> Travel(const std::vector<MappingKeyframe>& keyframes) {
  std::vector<double> travel(keyframes.size(), 0.0);
  for (std::size_t k = 1; k < keyframes.size(); ++k) {
    travel[k] = travel[k - 1] + (keyframes[k].T_prior.translation() - keyframes[k - 1].T_prior.translation()).norm();
  }
  return travel;
}

// Loop closures: for each keyframe, earlier keyframes at least `min_travel` back that the map's
// vocabulary retrieves near its present position (the odometry's drift bounds the radius); each
// verified by the ring's pose against that keyframe's points, as the localizer does. The best
// verified candidate per query becomes a loop edge.
std::vector<LoopEdge> FindLoops(const VisualMap& provisional, const robot::CameraRig& rig,
                                const MapBuilderOptions& options, const std::vector<MappingKeyframe>& keyframes,
                                MapBuildStats* stats) {
  const LoopClosureOptions& o = options.loops;
  const std::vector<double> travel = Travel(keyframes);
  LocalizerOptions localizer_options;
  localizer_options.features = options.features;
  localizer_options.retrieval = Retrieval::kCombined;
  localizer_options.prior_radius = o.search_radius + o.search_radius_per_m * (travel.empty() ? 0.0 : travel.back());
  localizer_options.pose.min_inliers = o.min_inliers;
  const VisualLocalizer localizer(provisional, rig, localizer_options);
  std::vector<LoopEdge> loops;
  for (std::size_t q = 0; q < keyframes.size(); ++q) {
    VisualLocalizer::FrameFeatures features;
    std::vector<cv::Mat> descriptors;
    for (std::size_t c = 0; c < keyframes[q].images.size(); ++c) {
      const MappingImage& image = keyframes[q].images[c];
      for (const auto& bearing : image.bearings) {
        features.camera.push_back(static_cast<int>(c));
        features.bearings.push_back(bearing);
      }
      if (image.descriptors.rows > 0) descriptors.push_back(image.descriptors);
    }
    if (descriptors.empty()) continue;
    cv::vconcat(descriptors, features.descriptors);
    localizer.AssignWords(&features);
    const Eigen::Vector2d position = keyframes[q].T_map_base.translation().head<2>();
    std::vector<int> candidates;
    for (int c : localizer.Retrieve(features, position, Retrieval::kCombined, 8 * o.candidates)) {
      const double since = travel[q] - travel[static_cast<std::size_t>(c)];
      const double radius = o.search_radius + o.search_radius_per_m * since;
      const Eigen::Vector2d there = keyframes[static_cast<std::size_t>(c)].T_map_base.translation().head<2>();
      if (since >= o.min_travel && (there - position).norm() <= radius) candidates.push_back(c);
      if (static_cast<int>(candidates.size()) == o.candidates) break;
    }
    std::optional<LoopEdge> best;
    for (int c : candidates) {
      ++stats->loops_tried;
      const RigPoseResult pose =
          EstimateRigPose(localizer.Match(features, {c}), localizer.T_base_camera(), localizer_options.pose);
      const int inliers = static_cast<int>(pose.inliers.size());
      if (!pose.success || inliers < o.min_inliers || (best && best->inliers >= inliers)) continue;
      best = LoopEdge{static_cast<int>(q), c, inliers,
                      keyframes[static_cast<std::size_t>(c)].T_map_base.inverse() * pose.T_map_base, 1.0};
    }
    if (best) loops.push_back(*best);
  }
  return loops;
}

}  // namespace

double SurveyedShape::SignedDistance(const Eigen::Vector3d& point) const {
  // Into the shape's own frame.
  const Eigen::Vector3d d = point - centre;
  const double c = std::cos(yaw), s = std::sin(yaw);
  const Eigen::Vector3d p(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
  const Eigen::Vector3d half = size / 2;
  switch (kind) {
    case Kind::kBox: {
      const Eigen::Vector3d q = p.cwiseAbs() - half;
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    case Kind::kCylinder: {
      const double k = std::hypot(p.x() / half.x(), p.y() / half.y());
      const double radial = k > 1e-9 ? (k - 1.0) * std::hypot(p.x(), p.y()) / k : -std::min(half.x(), half.y());
      const Eigen::Vector2d q(radial, std::abs(p.z()) - half.z());
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    case Kind::kEllipsoid: {
      const double k0 = p.cwiseQuotient(half).norm();
      const double k1 = p.cwiseQuotient(half.cwiseProduct(half)).norm();
      return k1 > 1e-12 ? k0 * (k0 - 1.0) / k1 : -half.minCoeff();
    }
  }
  return 0.0;
}

MapBuilder::MapBuilder(const robot::CameraRig& rig, const MapBuilderOptions& options) : rig_(rig), options_(options) {}

bool MapBuilder::WantsFrame(const Eigen::Isometry3d& T) const {
  if (keyframes_.empty()) return true;
  const Eigen::Isometry3d& last = keyframes_.back().T_prior;
  return (T.translation() - last.translation()).norm() >= options_.keyframe_distance ||
         RotationAngle(last.linear().transpose() * T.linear()) >= options_.keyframe_angle;
}

bool MapBuilder::AddFrame(const messages::RingFrame& frame, const Eigen::Isometry3d& T_map_base) {
  ++stats_.frames;
  if (!WantsFrame(T_map_base)) return false;
  const auto start = Clock::now();
  std::vector<MappingImage> images(static_cast<std::size_t>(rig_.size()));
  for (const auto& image : frame.images) {
    if (image.camera_index >= 0 && image.camera_index < rig_.size()) {
      images[static_cast<std::size_t>(image.camera_index)] =
          ExtractImageFeatures(image, rig_.camera(image.camera_index).intrinsics, options_.features);
    }
  }
  stats_.seconds_features += SecondsSince(start);
  AddKeyframe(frame.stamp, std::move(images), T_map_base);
  return true;
}

void MapBuilder::AddKeyframe(double stamp, std::vector<MappingImage> images, const Eigen::Isometry3d& T_map_base) {
  images.resize(static_cast<std::size_t>(rig_.size()));
  keyframes_.push_back({stamp, T_map_base, T_map_base, std::move(images)});
}

VisualMap MapBuilder::Build(const std::string& garden, MapBuildStats* stats) {
  const bool odometry = options_.poses == KeyframePoses::kOdometry;
  auto start = Clock::now();
  std::vector<ImageMatch> matches = MatchKeyframes(
      keyframes_, rig_, odometry ? options_.odometry_epipolar_angle : options_.epipolar_angle, options_, &stats_);
  std::vector<PointTrack> points =
      TriangulateTracks(keyframes_, rig_, matches, options_, 4.0 * options_.epipolar_angle, &stats_);
  stats_.seconds_matching = SecondsSince(start);
  start = Clock::now();
  WheelScales scales = MakeWheelScales(keyframes_, options_.odometry);
  if (!odometry) {
    AdjustTwice(rig_, options_, keyframes_, points, scales, &stats_);
    stats_.seconds_adjustment = SecondsSince(start);
  } else {
    // A provisional map (one adjustment, outliers dropped) for retrieval and the loops' poses.
    std::vector<double> errors;
    Adjust(rig_, options_, keyframes_, points, scales, &errors);
    RemoveOutliers(errors, options_.max_reprojection_error, points);
    stats_.seconds_adjustment = SecondsSince(start);
    // Close the loops on it, then match again where the corrected poses allow.
    start = Clock::now();
    loops_ = FindLoops(MakeMap(garden, rig_, options_, keyframes_, points), rig_, options_, keyframes_, &stats_);
    std::vector<Eigen::Isometry3d> provisional;
    for (const auto& k : keyframes_) provisional.push_back(k.T_map_base);
    OptimizePoseGraph(options_, keyframes_, loops_);
    // Loops the pose graph down-weights below 0.5 are dropped, and the graph solved without them.
    std::vector<LoopEdge> accepted;
    for (const auto& loop : loops_) {
      if (loop.weight >= 0.5) accepted.push_back(loop);
    }
    if (accepted.size() < loops_.size()) {
      for (std::size_t k = 0; k < keyframes_.size(); ++k) keyframes_[k].T_map_base = provisional[k];
      OptimizePoseGraph(options_, keyframes_, accepted);
    }
    std::vector<ImageMatch> kept;
    for (const auto& m : matches) {
      if (EpipolarAngle(keyframes_, rig_, m) <= options_.epipolar_angle) kept.push_back(m);
    }
    std::srand(1);  // FLANN's trees for the loop keyframes: independent of how much the first pass drew
    for (const auto& loop : accepted) {
      ++stats_.loops_accepted;
      for (int k = std::max(0, loop.match - 1); k <= std::min(keyframes() - 1, loop.match + 1); ++k) {
        MatchKeyframePair(keyframes_, rig_, k, loop.query, options_.epipolar_angle, options_, &stats_, &kept);
      }
    }
    matches = std::move(kept);
    stats_.seconds_loops = SecondsSince(start);
    start = Clock::now();
    points = TriangulateTracks(keyframes_, rig_, matches, options_, 4.0 * options_.epipolar_angle, &stats_);
    AdjustTwice(rig_, options_, keyframes_, points, scales, &stats_);
    stats_.seconds_adjustment += SecondsSince(start);
    stats_.scale_stretches = static_cast<int>(scales.scale.size());
    stats_.scale_min = *std::min_element(scales.scale.begin(), scales.scale.end());
    stats_.scale_max = *std::max_element(scales.scale.begin(), scales.scale.end());
    if (!shapes_.empty()) {
      stats_.tie_correction =
          TieToShapes(points, shapes_, options_.tie, &stats_.tie_points, &stats_.tie_residual_median);
      Eigen::Isometry3d T_tie = Eigen::Isometry3d::Identity();
      T_tie.linear() = Eigen::AngleAxisd(stats_.tie_correction.z(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
      T_tie.translation() << stats_.tie_correction.x(), stats_.tie_correction.y(), 0.0;
      for (auto& k : keyframes_) k.T_map_base = T_tie * k.T_map_base;
      for (auto& p : points) p.position = T_tie * p.position;
    }
  }
  stats_.gaps = FindGaps(keyframes_.size(), points, options_.min_shared_points);
  start = Clock::now();
  VisualMap map = MakeMap(garden, rig_, options_, keyframes_, points);
  stats_.seconds_vocabulary = SecondsSince(start);
  stats_.keyframes = static_cast<int>(map.keyframes.size());
  stats_.points = static_cast<int>(map.points.size());
  stats_.observations = static_cast<int>(map.observations.size());
  stats_.mean_track_length =
      map.points.empty() ? 0.0 : static_cast<double>(map.observations.size()) / map.points.size();
  if (stats != nullptr) *stats = stats_;
  return map;
}

}  // namespace trimbot::visual_localization
