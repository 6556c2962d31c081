#include "trimbot/visual_localization/map_builder.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <opencv2/features2d.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <numeric>
#include <optional>

#include "trimbot/common/rotation.h"

namespace trimbot::visual_localization {
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double RotationAngle(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

// One feature of one image of one keyframe.
struct FeatureRef {
  int keyframe = 0, camera = 0, feature = 0;
};

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

// Observed normalized image point vs the projection of a map point, in pixels / sigma.
struct ReprojectionError {
  Eigen::Vector2d observed;  // normalized (x/z, y/z) in the camera
  Eigen::Matrix3d R_cam_base;
  Eigen::Vector3d t_cam_base;
  double scale;  // focal length / pixel sigma

  template <typename T>
  bool operator()(const T* const pose, const T* const point, T* residual) const {
    // pose: angle-axis of R_map_base (3), translation of base_link in the map (3).
    T p[3] = {point[0] - pose[3], point[1] - pose[4], point[2] - pose[5]};
    T inverse[3] = {-pose[0], -pose[1], -pose[2]};
    T in_base[3];
    ceres::AngleAxisRotatePoint(inverse, p, in_base);
    Eigen::Matrix<T, 3, 1> in_camera =
        R_cam_base.cast<T>() * Eigen::Matrix<T, 3, 1>(in_base[0], in_base[1], in_base[2]) + t_cam_base.cast<T>();
    if (in_camera(2) < T(1e-3)) in_camera(2) = T(1e-3);
    residual[0] = T(scale) * (in_camera(0) / in_camera(2) - T(observed.x()));
    residual[1] = T(scale) * (in_camera(1) / in_camera(2) - T(observed.y()));
    return true;
  }
};

// The survey's pose of a keyframe as a soft constraint.
struct PosePrior {
  Eigen::Matrix3d R_prior_transposed;
  Eigen::Vector3d t_prior;
  double rotation_sigma, position_sigma;

  template <typename T>
  bool operator()(const T* const pose, T* residual) const {
    T R[9];
    ceres::AngleAxisToRotationMatrix(pose, R);  // column-major
    Eigen::Map<const Eigen::Matrix<T, 3, 3>> R_map_base(R);
    const Eigen::Matrix<T, 3, 3> delta = R_prior_transposed.cast<T>() * R_map_base;
    T delta_cm[9];
    Eigen::Map<Eigen::Matrix<T, 3, 3>> delta_map(delta_cm);
    delta_map = delta;
    T angle_axis[3];
    ceres::RotationMatrixToAngleAxis(delta_cm, angle_axis);
    for (int i = 0; i < 3; ++i) {
      residual[i] = angle_axis[i] / T(rotation_sigma);
      residual[3 + i] = (pose[3 + i] - T(t_prior(i))) / T(position_sigma);
    }
    return true;
  }
};

// ---- matching ----------------------------------------------------------------------------------

struct ImageMatch {
  FeatureRef a, b;
};

// Matches of image (ka, ca) with image (kb, cb): ratio test, then the epipolar angle of the
// survey poses (the rays must lie near the plane through both camera centres).
void MatchImages(const std::vector<MappingKeyframe>& keyframes, const robot::CameraRig& rig, int ka, int ca, int kb,
                 int cb, const MapBuilderOptions& options, std::vector<ImageMatch>* matches) {
  const MappingImage& A = keyframes[ka].images[ca];
  const MappingImage& B = keyframes[kb].images[cb];
  if (A.descriptors.rows < 2 || B.descriptors.rows < 2) return;
  const Eigen::Isometry3d Ta = keyframes[ka].T_map_base * rig.camera(ca).T_base_camera;
  const Eigen::Isometry3d Tb = keyframes[kb].T_map_base * rig.camera(cb).T_base_camera;
  const Eigen::Vector3d baseline = Tb.translation() - Ta.translation();
  if (baseline.norm() < 0.05) return;  // no parallax to triangulate from
  cv::FlannBasedMatcher matcher(cv::makePtr<cv::flann::KDTreeIndexParams>(4), cv::makePtr<cv::flann::SearchParams>(32));
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(A.descriptors, B.descriptors, knn, 2);
  for (const auto& pair : knn) {
    if (pair.size() < 2 || pair[0].distance > options.ratio * pair[1].distance) continue;
    const Eigen::Vector3d ra = Ta.linear() * A.bearings[pair[0].queryIdx];
    const Eigen::Vector3d rb = Tb.linear() * B.bearings[pair[0].trainIdx];
    const Eigen::Vector3d normal = baseline.cross(ra);
    if (normal.norm() < 1e-9) continue;
    if (std::abs(std::asin(std::clamp(normal.normalized().dot(rb), -1.0, 1.0))) > options.epipolar_angle) continue;
    matches->push_back({{ka, ca, pair[0].queryIdx}, {kb, cb, pair[0].trainIdx}});
  }
}

std::vector<ImageMatch> MatchKeyframes(const std::vector<MappingKeyframe>& keyframes, const robot::CameraRig& rig,
                                       const MapBuilderOptions& options, MapBuildStats* stats) {
  std::srand(1);  // FLANN's randomized trees draw from rand(): the same map from the same drive
  std::vector<ImageMatch> matches;
  const int n = static_cast<int>(keyframes.size());
  for (int ka = 0; ka < n; ++ka) {
    for (int kb = ka + 1; kb < n && kb <= ka + options.match_next_keyframes; ++kb) {
      for (int ca = 0; ca < rig.size(); ++ca) {
        for (int cb = 0; cb < rig.size(); ++cb) {
          const Eigen::Vector3d axis_a = (keyframes[ka].T_map_base * rig.camera(ca).T_base_camera).linear().col(2);
          const Eigen::Vector3d axis_b = (keyframes[kb].T_map_base * rig.camera(cb).T_base_camera).linear().col(2);
          if (std::acos(std::clamp(axis_a.dot(axis_b), -1.0, 1.0)) > options.max_camera_angle) continue;
          MatchImages(keyframes, rig, ka, ca, kb, cb, options, &matches);
          ++stats->images_matched;
        }
      }
    }
  }
  stats->matches = static_cast<int>(matches.size());
  return matches;
}

// ---- tracks and points -------------------------------------------------------------------------

using Track = std::vector<FeatureRef>;

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

// Midpoint triangulation from the survey poses; nullopt when the rays do not make a good point.
std::optional<Eigen::Vector3d> Triangulate(const std::vector<MappingKeyframe>& keyframes, const robot::CameraRig& rig,
                                           const Track& track, const MapBuilderOptions& options) {
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
        4.0 * options.epipolar_angle) {
      return std::nullopt;
    }
  }
  return X;
}

// ---- adjustment --------------------------------------------------------------------------------

struct PointTrack {
  Eigen::Vector3d position;
  Track track;
};

// Bundle adjustment of keyframe poses and points, the poses held near `survey` (one per keyframe);
// returns the RMS reprojection error in pixels and each observation's error (px; points in order,
// each point's track in order) in `errors`.
double Adjust(const robot::CameraRig& rig, const MapBuilderOptions& options,
              const std::vector<Eigen::Isometry3d>& survey, std::vector<MappingKeyframe>& keyframes,
              std::vector<PointTrack>& points, std::vector<double>* errors) {
  std::vector<std::array<double, 6>> poses(keyframes.size());
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    const Eigen::AngleAxisd aa(keyframes[k].T_map_base.linear());
    const Eigen::Vector3d w = aa.angle() * aa.axis(), t = keyframes[k].T_map_base.translation();
    poses[k] = {w.x(), w.y(), w.z(), t.x(), t.y(), t.z()};
  }
  ceres::Problem problem;
  std::vector<std::pair<ceres::ResidualBlockId, double>> blocks;  // with their pixel scale
  for (auto& p : points) {
    for (const auto& r : p.track) {
      const robot::CameraCalibration& camera = rig.camera(r.camera);
      const Eigen::Isometry3d T_cam_base = camera.T_base_camera.inverse();
      const Eigen::Vector3d& bearing = keyframes[r.keyframe].images[r.camera].bearings[r.feature];
      const double scale = camera.intrinsics.fx / options.pixel_sigma;
      auto* cost = new ceres::AutoDiffCostFunction<ReprojectionError, 2, 6, 3>(
          new ReprojectionError{bearing.head<2>() / bearing.z(), T_cam_base.linear(), T_cam_base.translation(), scale});
      blocks.push_back(
          {problem.AddResidualBlock(cost, new ceres::HuberLoss(2.0), poses[r.keyframe].data(), p.position.data()),
           options.pixel_sigma});
    }
  }
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    auto* prior = new ceres::AutoDiffCostFunction<PosePrior, 6, 6>(
        new PosePrior{survey[k].linear().transpose(), survey[k].translation(), options.survey_rotation_sigma,
                      options.survey_position_sigma});
    problem.AddResidualBlock(prior, nullptr, poses[k].data());
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_SCHUR;
  solver.max_num_iterations = options.adjustment_iterations;
  solver.num_threads = 1;  // one thread: the same map, bit for bit, from the same drive
  ceres::Solver::Summary summary;
  if (!blocks.empty()) ceres::Solve(solver, &problem, &summary);
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    const Eigen::Vector3d w(poses[k][0], poses[k][1], poses[k][2]);
    keyframes[k].T_map_base.linear() = RotationFromVector(w);
    keyframes[k].T_map_base.translation() << poses[k][3], poses[k][4], poses[k][5];
  }
  // RMS of the pixel residuals (the cost functions are scaled by 1/sigma).
  double sum = 0.0;
  errors->clear();
  for (const auto& [id, sigma] : blocks) {
    double residual[2];
    problem.EvaluateResidualBlock(id, false, nullptr, residual, nullptr);
    const double squared = (residual[0] * residual[0] + residual[1] * residual[1]) * sigma * sigma;
    sum += squared;
    errors->push_back(std::sqrt(squared));
  }
  return blocks.empty() ? 0.0 : std::sqrt(sum / (2.0 * blocks.size()));
}

// Drops observations with an error above `max_error` (px; `errors` as Adjust gives them), then
// points seen fewer than twice. Returns how many observations were dropped.
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
    if (track.size() >= 2) kept.push_back({p.position, std::move(track)});
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

}  // namespace

MapBuilder::MapBuilder(const robot::CameraRig& rig, const MapBuilderOptions& options) : rig_(rig), options_(options) {}

bool MapBuilder::WantsFrame(const Eigen::Isometry3d& T) const {
  if (keyframes_.empty()) return true;
  const Eigen::Isometry3d& last = keyframes_.back().T_map_base;
  return (T.translation() - last.translation()).norm() >= options_.keyframe_distance ||
         RotationAngle(last.linear().transpose() * T.linear()) >= options_.keyframe_angle;
}

bool MapBuilder::AddFrame(const messages::RingFrame& frame, const Eigen::Isometry3d& T_map_base_survey) {
  ++stats_.frames;
  if (!WantsFrame(T_map_base_survey)) return false;
  const auto start = Clock::now();
  MappingKeyframe keyframe;
  keyframe.stamp = frame.stamp;
  keyframe.T_map_base = T_map_base_survey;
  keyframe.images.resize(static_cast<std::size_t>(rig_.size()));
  for (const auto& image : frame.images) {
    if (image.camera_index >= 0 && image.camera_index < rig_.size()) {
      keyframe.images[static_cast<std::size_t>(image.camera_index)] =
          ExtractImageFeatures(image, rig_.camera(image.camera_index).intrinsics, options_.features);
    }
  }
  keyframes_.push_back(std::move(keyframe));
  stats_.seconds_features += Since(start);
  return true;
}

VisualMap MapBuilder::Build(const std::string& garden, MapBuildStats* stats) {
  auto start = Clock::now();
  const std::vector<ImageMatch> matches = MatchKeyframes(keyframes_, rig_, options_, &stats_);
  const std::vector<Track> tracks = JoinTracks(keyframes_, matches);
  stats_.tracks = static_cast<int>(tracks.size());
  std::vector<PointTrack> points;
  for (const auto& track : tracks) {
    if (const auto X = Triangulate(keyframes_, rig_, track, options_)) points.push_back({*X, track});
  }
  stats_.seconds_matching = Since(start);
  start = Clock::now();
  // Adjust, drop the observations the adjusted map cannot explain (wrong matches, silhouettes that
  // move with the viewpoint), adjust again.
  std::vector<Eigen::Isometry3d> survey;  // both passes are held to the survey, not the first pass
  for (const auto& keyframe : keyframes_) survey.push_back(keyframe.T_map_base);
  std::vector<double> errors;
  Adjust(rig_, options_, survey, keyframes_, points, &errors);
  stats_.outlier_observations = RemoveOutliers(errors, options_.max_reprojection_error, points);
  stats_.reprojection_rmse_px = Adjust(rig_, options_, survey, keyframes_, points, &errors);
  stats_.seconds_adjustment = Since(start);

  VisualMap map;
  map.garden = garden;
  map.rig_signature = RigSignature(rig_);
  map.descriptor = options_.features.descriptor;
  for (std::size_t k = 0; k < keyframes_.size(); ++k) {
    map.keyframes.push_back({static_cast<int>(k), keyframes_[k].stamp, keyframes_[k].T_map_base});
  }
  std::vector<cv::Mat> descriptors;
  for (std::size_t i = 0; i < points.size(); ++i) {
    cv::Mat mean = cv::Mat::zeros(1, 128, CV_32F);
    for (const auto& r : points[i].track) {
      const MappingImage& image = keyframes_[r.keyframe].images[r.camera];
      mean += image.descriptors.row(r.feature);
      map.observations.push_back({r.keyframe, r.camera, static_cast<int>(i), image.pixels[r.feature]});
    }
    descriptors.push_back(mean / static_cast<double>(points[i].track.size()));
    map.points.push_back(points[i].position);
  }
  if (!descriptors.empty()) cv::vconcat(descriptors, map.descriptors);
  start = Clock::now();
  if (!map.descriptors.empty()) map.vocabulary = TrainVocabulary(map.descriptors, options_.vocabulary_words);
  stats_.seconds_vocabulary = Since(start);
  stats_.keyframes = static_cast<int>(map.keyframes.size());
  stats_.points = static_cast<int>(map.points.size());
  stats_.observations = static_cast<int>(map.observations.size());
  stats_.mean_track_length =
      map.points.empty() ? 0.0 : static_cast<double>(map.observations.size()) / map.points.size();
  if (stats != nullptr) *stats = stats_;
  return map;
}

}  // namespace trimbot::visual_localization
