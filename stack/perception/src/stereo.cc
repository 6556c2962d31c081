#include "trimbot/perception/stereo.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "trimbot/common/input_error.h"

namespace trimbot::perception {
namespace {

std::string SizeText(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }
std::string SizeText(const cv::Mat& image) { return SizeText(image.cols, image.rows); }

cv::Matx33d CameraMatrix(const robot::PinholeRadtan& camera) {
  return {camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0};
}

cv::Vec4d DistortionCoefficients(const robot::PinholeRadtan& camera) {
  return {camera.k1, camera.k2, camera.p1, camera.p2};
}

// RGB or grey image of the calibrated size -> grey.
cv::Mat ToGrey(const cv::Mat& image, const cv::Size& expected, int camera_index) {
  const std::string camera = "cam" + std::to_string(camera_index);
  if (image.size() != expected) {
    throw std::invalid_argument("stereo: the image of " + camera + " is " + SizeText(image) +
                                ", its calibration expects " + SizeText(expected.width, expected.height));
  }
  if (image.type() == CV_8UC1) return image;
  if (image.type() != CV_8UC3) {
    throw std::invalid_argument("stereo: the image of " + camera + " is not 8-bit RGB or grey");
  }
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_RGB2GRAY);
  return grey;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// StereoRectifier

StereoRectifier::StereoRectifier(const robot::CameraRig& rig, const robot::StereoPair& pair) : pair_(pair) {
  for (int index : {pair.left, pair.right}) {
    if (index < 0 || index >= rig.size()) {
      throw InputError(rig.source(), "stereo pair (" + std::to_string(pair.left) + ", " + std::to_string(pair.right) +
                                         ") names camera " + std::to_string(index) + ", the rig has cameras 0.." +
                                         std::to_string(rig.size() - 1));
    }
  }
  if (pair.left == pair.right) {
    throw InputError(rig.source(), "stereo pair uses camera " + std::to_string(pair.left) + " twice");
  }
  const robot::CameraCalibration& left = rig.camera(pair.left);
  const robot::CameraCalibration& right = rig.camera(pair.right);
  left_camera_ = left.intrinsics;
  image_size_ = cv::Size(left.intrinsics.width, left.intrinsics.height);
  if (right.intrinsics.width != left.intrinsics.width || right.intrinsics.height != left.intrinsics.height) {
    throw std::invalid_argument("stereo pair (" + left.name + ", " + right.name + "): image sizes differ (" +
                                SizeText(left.intrinsics.width, left.intrinsics.height) + " and " +
                                SizeText(right.intrinsics.width, right.intrinsics.height) + ")");
  }

  // OpenCV's convention: x_right = R x_left + T.
  const Eigen::Isometry3d T_right_left = right.T_base_camera.inverse() * left.T_base_camera;
  cv::Matx33d R;
  cv::Vec3d T;
  for (int r = 0; r < 3; ++r) {
    T[r] = T_right_left.translation()[r];
    for (int c = 0; c < 3; ++c) R(r, c) = T_right_left.linear()(r, c);
  }
  cv::Mat R1, R2, P1, P2, Q;
  // alpha 0: every rectified pixel sees the scene (no black borders to confuse the matcher). With
  // the ring's barrel distortion this keeps about 74 degrees horizontally, more than the 72
  // degrees between pairs, and loses only the image corners.
  constexpr double kAlpha = 0.0;
  cv::stereoRectify(CameraMatrix(left.intrinsics), DistortionCoefficients(left.intrinsics),
                    CameraMatrix(right.intrinsics), DistortionCoefficients(right.intrinsics), image_size_, R, T, R1, R2,
                    P1, P2, Q, cv::CALIB_ZERO_DISPARITY, kAlpha, image_size_);
  focal_length_ = P1.at<double>(0, 0);
  principal_point_ = {P1.at<double>(0, 2), P1.at<double>(1, 2)};
  baseline_ = -P2.at<double>(0, 3) / P2.at<double>(0, 0);
  // stereoRectify makes the pair vertical when the cameras are above each other, and a right
  // camera on the left gives negative disparities: neither is a left/right pair the matcher handles.
  if (std::abs(P2.at<double>(1, 3)) > 1e-9 * std::abs(P2.at<double>(0, 3)) + 1e-12 || !(baseline_ > 0.0)) {
    throw InputError(rig.source(), "stereo pair (" + left.name + ", " + right.name + "): " + right.name +
                                       " is not to the right of " + left.name);
  }

  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R_rectified_left_(r, c) = R1.at<double>(r, c);
  }
  Eigen::Isometry3d T_left_rectified = Eigen::Isometry3d::Identity();
  T_left_rectified.linear() = R_rectified_left_.transpose();
  T_base_rectified_left_ = left.T_base_camera * T_left_rectified;

  cv::initUndistortRectifyMap(CameraMatrix(left.intrinsics), DistortionCoefficients(left.intrinsics), R1, P1,
                              image_size_, CV_32FC1, left_map_x_, left_map_y_);
  cv::Mat right_map_x, right_map_y;
  cv::initUndistortRectifyMap(CameraMatrix(right.intrinsics), DistortionCoefficients(right.intrinsics), R2, P2,
                              image_size_, CV_32FC1, right_map_x, right_map_y);
  cv::convertMaps(left_map_x_, left_map_y_, left_map_fixed_, left_map_interpolation_, CV_16SC2);
  cv::convertMaps(right_map_x, right_map_y, right_map_fixed_, right_map_interpolation_, CV_16SC2);
}

StereoRectifier::RectifiedPair StereoRectifier::Rectify(const cv::Mat& left, const cv::Mat& right) const {
  RectifiedPair out;
  cv::remap(ToGrey(left, image_size_, pair_.left), out.left, left_map_fixed_, left_map_interpolation_,
            cv::INTER_LINEAR);
  cv::remap(ToGrey(right, image_size_, pair_.right), out.right, right_map_fixed_, right_map_interpolation_,
            cv::INTER_LINEAR);
  return out;
}

// ---------------------------------------------------------------------------------------------
// StereoMatcher

struct StereoMatcher::Impl {
  cv::Ptr<cv::StereoSGBM> sgbm;
};

StereoMatcher::StereoMatcher(const StereoOptions& options) : options_(options), impl_(std::make_unique<Impl>()) {
  const int disparities = options.EffectiveDisparities();
  if (disparities <= 0 || disparities % 16 != 0) {
    throw std::invalid_argument("stereo: disparities must be a positive multiple of 16, not " +
                                std::to_string(disparities));
  }
  if (options.block_size < 1 || options.block_size % 2 == 0) {
    throw std::invalid_argument("stereo: block size must be odd and positive, not " +
                                std::to_string(options.block_size));
  }
  if (options.texture_window < 1 || options.texture_window % 2 == 0) {
    throw std::invalid_argument("stereo: texture window must be odd and positive, not " +
                                std::to_string(options.texture_window));
  }
  const int area = options.block_size * options.block_size;  // grey images: one channel
  impl_->sgbm = cv::StereoSGBM::create(/*minDisparity=*/0, disparities, options.block_size, 8 * area, 32 * area,
                                       options.max_left_right_difference, /*preFilterCap=*/63, options.uniqueness_ratio,
                                       options.speckle_window, options.speckle_range,
                                       options.dense ? cv::StereoSGBM::MODE_HH : cv::StereoSGBM::MODE_SGBM_3WAY);
}

StereoMatcher::~StereoMatcher() = default;
StereoMatcher::StereoMatcher(StereoMatcher&&) noexcept = default;
StereoMatcher& StereoMatcher::operator=(StereoMatcher&&) noexcept = default;

cv::Mat StereoMatcher::Compute(const cv::Mat& left_rectified, const cv::Mat& right_rectified) const {
  if (left_rectified.type() != CV_8UC1 || right_rectified.type() != CV_8UC1 ||
      left_rectified.size() != right_rectified.size()) {
    throw std::invalid_argument("stereo matcher: needs two grey images of one size, got " + SizeText(left_rectified) +
                                " and " + SizeText(right_rectified));
  }
  cv::Mat fixed_point;  // CV_16S, 4 fractional bits; (minDisparity - 1) * 16 marks no estimate
  impl_->sgbm->compute(left_rectified, right_rectified, fixed_point);
  cv::Mat texture;
  if (options_.min_texture > 0.0) {
    cv::Mat gradient;
    cv::Sobel(left_rectified, gradient, CV_16S, 1, 0, 1);  // I(u+1) - I(u-1)
    gradient = cv::abs(gradient);
    cv::boxFilter(gradient, texture, CV_32F, cv::Size(options_.texture_window, options_.texture_window),
                  cv::Point(-1, -1), true, cv::BORDER_REFLECT);
    texture *= 0.5;  // grey levels per px
  }
  cv::Mat disparity(fixed_point.size(), CV_32F);
  const float no_estimate = std::numeric_limits<float>::quiet_NaN();
  const float min_texture = static_cast<float>(options_.min_texture);
  for (int v = 0; v < fixed_point.rows; ++v) {
    const auto* in = fixed_point.ptr<std::int16_t>(v);
    const float* texture_row = texture.empty() ? nullptr : texture.ptr<float>(v);
    auto* out = disparity.ptr<float>(v);
    for (int u = 0; u < fixed_point.cols; ++u) {
      const bool blank = texture_row != nullptr && texture_row[u] < min_texture;
      out[u] = in[u] < 0 || blank ? no_estimate : in[u] / 16.0f;
    }
  }
  return disparity;
}

// ---------------------------------------------------------------------------------------------
// Disparity -> points with covariance

namespace {

void CheckDisparity(const cv::Mat& disparity, const StereoRectifier& rectifier, const StereoOptions& options) {
  if (disparity.type() != CV_32FC1 || disparity.size() != rectifier.image_size()) {
    throw std::invalid_argument("DisparityToCloud: needs a CV_32F disparity of " +
                                SizeText(rectifier.image_size().width, rectifier.image_size().height) + ", got " +
                                SizeText(disparity));
  }
  if (options.stride < 1) throw std::invalid_argument("DisparityToCloud: stride must be at least 1");
}

// Calls point(u, v, d, z) for every pixel that becomes a point.
template <class PointFunction>
void ForEachCloudPixel(const cv::Mat& disparity, double f_times_b, const StereoOptions& options, PointFunction point) {
  for (int v = 0; v < disparity.rows; v += options.stride) {
    const float* row = disparity.ptr<float>(v);
    for (int u = 0; u < disparity.cols; u += options.stride) {
      const double d = row[u];
      if (!(d > 0.0)) continue;  // NaN (no estimate) or at infinity
      const double z = f_times_b / d;
      if (z < options.min_depth || z > options.max_depth) continue;
      point(u, v, d, z);
    }
  }
}

std::size_t CountCloudPoints(const cv::Mat& disparity, const StereoRectifier& rectifier, const StereoOptions& options) {
  std::size_t count = 0;
  ForEachCloudPixel(disparity, rectifier.focal_length() * rectifier.baseline(), options,
                    [&count](int, int, double, double) { ++count; });
  return count;
}

// Appends to `cloud`; the caller reserves (a ring cloud is tens of MB: growing it by copies costs
// more than the stereo).
void AppendCloud(const cv::Mat& disparity, const StereoRectifier& rectifier, const StereoOptions& options,
                 PointCloud* cloud) {
  const double f = rectifier.focal_length();
  const double cx = rectifier.principal_point().x(), cy = rectifier.principal_point().y();
  const Eigen::Isometry3d& T_base_rectified = rectifier.T_base_rectified_left();
  const Eigen::Matrix3d R = T_base_rectified.linear();
  const double pixel_variance = options.pixel_sigma * options.pixel_sigma;
  const double disparity_variance = options.disparity_sigma * options.disparity_sigma;
  // With X = (u - cx) B / d, Y = (v - cy) B / d, Z = f B / d and P = (X, Y, Z):
  //   J = d(X,Y,Z)/d(u,v,d) = [B/d 0 -X/d; 0 B/d -Y/d; 0 0 -Z/d]
  //   J diag(s_u^2, s_v^2, s_d^2) J^T = (B/d)^2 s_px^2 (I - e_z e_z^T) + (s_d/d)^2 P P^T,
  // and rotated into base_link e_z becomes the optical axis R e_z and P becomes R P.
  const Eigen::Matrix3d across_axis = Eigen::Matrix3d::Identity() - R.col(2) * R.col(2).transpose();
  ForEachCloudPixel(disparity, f * rectifier.baseline(), options, [&](int u, int v, double d, double z) {
    const Eigen::Vector3d in_rectified((u - cx) * z / f, (v - cy) * z / f, z);
    const Eigen::Vector3d rotated = R * in_rectified;
    const double pixel_scale = z / f;  // = B / d
    const Eigen::Matrix3d covariance = (pixel_scale * pixel_scale * pixel_variance) * across_axis +
                                       (disparity_variance / (d * d)) * rotated * rotated.transpose();
    cloud->Add(rotated + T_base_rectified.translation(), covariance);
  });
}

}  // namespace

PointCloud DisparityToCloud(const cv::Mat& disparity, const StereoRectifier& rectifier, const StereoOptions& options) {
  CheckDisparity(disparity, rectifier, options);
  PointCloud cloud;
  const std::size_t count = CountCloudPoints(disparity, rectifier, options);
  cloud.points.reserve(count);
  cloud.covariances.reserve(count);
  AppendCloud(disparity, rectifier, options, &cloud);
  return cloud;
}

cv::Mat ImageToMat(const messages::Image& image) {
  int type = 0;
  if (image.encoding == "rgb8") {
    type = CV_8UC3;
  } else if (image.encoding == "mono8") {
    type = CV_8UC1;
  } else {
    throw std::invalid_argument("image from cam" + std::to_string(image.camera_index) + ": encoding '" +
                                image.encoding + "' is not rgb8 or mono8");
  }
  const std::size_t expected =
      static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * (type == CV_8UC3 ? 3 : 1);
  if (image.width <= 0 || image.height <= 0 || image.data.size() != expected) {
    throw std::invalid_argument("image from cam" + std::to_string(image.camera_index) + ": " +
                                std::to_string(image.data.size()) + " bytes for " +
                                SizeText(image.width, image.height) + " " + image.encoding);
  }
  cv::Mat mat(image.height, image.width, type);
  std::copy(image.data.begin(), image.data.end(), mat.data);
  return mat;
}

// ---------------------------------------------------------------------------------------------
// The ring

RingStereo::RingStereo(const robot::CameraRig& rig, const StereoOptions& options)
    : options_(options), matcher_(options) {
  for (const robot::StereoPair& pair : rig.StereoPairs()) rectifiers_.emplace_back(rig, pair);
}

namespace {

const messages::Image& FindImage(const messages::RingFrame& frame, int camera_index, int pair_index) {
  for (const messages::Image& image : frame.images) {
    if (image.camera_index == camera_index) return image;
  }
  throw std::invalid_argument("ring frame at t=" + std::to_string(frame.stamp) + " s has no image from cam" +
                              std::to_string(camera_index) + " (stereo pair " + std::to_string(pair_index) + ")");
}

}  // namespace

cv::Mat RingStereo::PairDisparity(const messages::RingFrame& frame, int pair_index) const {
  if (pair_index < 0 || pair_index >= static_cast<int>(rectifiers_.size())) {
    throw std::out_of_range("RingStereo: no stereo pair " + std::to_string(pair_index));
  }
  const StereoRectifier& rectifier = rectifiers_[static_cast<std::size_t>(pair_index)];
  const messages::Image& left = FindImage(frame, rectifier.pair().left, pair_index);
  const messages::Image& right = FindImage(frame, rectifier.pair().right, pair_index);
  const StereoRectifier::RectifiedPair rectified = rectifier.Rectify(ImageToMat(left), ImageToMat(right));
  return matcher_.Compute(rectified.left, rectified.right);
}

RingStereo::PairResult RingStereo::ComputePair(const messages::RingFrame& frame, int pair_index) const {
  PairResult result;
  result.disparity = PairDisparity(frame, pair_index);
  result.cloud = DisparityToCloud(result.disparity, rectifiers_[static_cast<std::size_t>(pair_index)], options_);
  return result;
}

PointCloud RingStereo::RingCloud(const messages::RingFrame& frame) const {
  PointCloud ring;
  RingCloud(frame, &ring);
  return ring;
}

void RingStereo::RingCloud(const messages::RingFrame& frame, PointCloud* ring) const {
  // Check every image first: a missing camera is reported before any matching.
  for (std::size_t k = 0; k < rectifiers_.size(); ++k) {
    FindImage(frame, rectifiers_[k].pair().left, static_cast<int>(k));
    FindImage(frame, rectifiers_[k].pair().right, static_cast<int>(k));
  }
  std::vector<cv::Mat> disparities;
  std::size_t total = 0;
  for (std::size_t k = 0; k < rectifiers_.size(); ++k) {
    disparities.push_back(PairDisparity(frame, static_cast<int>(k)));
    total += CountCloudPoints(disparities.back(), rectifiers_[k], options_);
  }
  ring->points.clear();
  ring->covariances.clear();
  ring->points.reserve(total);
  ring->covariances.reserve(total);
  for (std::size_t k = 0; k < rectifiers_.size(); ++k) AppendCloud(disparities[k], rectifiers_[k], options_, ring);
}

PointCloud RingCloud(const messages::RingFrame& frame, const robot::CameraRig& rig, const StereoOptions& options) {
  return RingStereo(rig, options).RingCloud(frame);
}

// ---------------------------------------------------------------------------------------------
// Ground

namespace {

// Least-squares plane through points (centroid and the direction of least spread), normal up.
GroundPlane PlaneThrough(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - centroid) * (p - centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  GroundPlane plane;
  plane.normal = solver.eigenvectors().col(0);  // eigenvalues ascending
  if (plane.normal.z() < 0.0) plane.normal = -plane.normal;
  plane.offset = -plane.normal.dot(centroid);
  return plane;
}

}  // namespace

std::optional<GroundPlane> FitGroundPlane(const PointCloud& cloud, const GroundFitOptions& options) {
  std::vector<Eigen::Vector3d> candidates;
  for (const Eigen::Vector3d& p : cloud.points) {
    if (std::abs(p.z()) < options.candidate_height) candidates.push_back(p);
  }
  if (candidates.size() < 3) return std::nullopt;
  // Hypotheses are scored on an evenly spaced subset: enough to rank planes, and the cost no
  // longer grows with the cloud. The winner is refined on all candidates.
  constexpr std::size_t kMaxScored = 20000;
  const std::size_t step = std::max<std::size_t>(1, candidates.size() / kMaxScored);
  const double min_normal_z = std::cos(options.max_tilt_degrees * M_PI / 180.0);
  // std::mt19937_64's output is fixed by the standard (distributions are not), so the hypotheses
  // are the same on every platform.
  std::mt19937_64 random(options.seed);
  const std::uint64_t n = candidates.size();
  std::optional<GroundPlane> best;
  int best_score = 0;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    const Eigen::Vector3d& a = candidates[random() % n];
    const Eigen::Vector3d& b = candidates[random() % n];
    const Eigen::Vector3d& c = candidates[random() % n];
    Eigen::Vector3d normal = (b - a).cross(c - a);
    if (normal.norm() < 1e-9) continue;  // repeated or collinear points
    normal.normalize();
    if (normal.z() < 0.0) normal = -normal;
    if (normal.z() < min_normal_z) continue;
    GroundPlane hypothesis;
    hypothesis.normal = normal;
    hypothesis.offset = -normal.dot(a);
    int score = 0;
    for (std::size_t i = 0; i < candidates.size(); i += step) {
      score += std::abs(hypothesis.Distance(candidates[i])) < options.inlier_distance ? 1 : 0;
    }
    if (score > best_score) {
      best_score = score;
      best = hypothesis;
    }
  }
  if (!best) return std::nullopt;
  std::vector<Eigen::Vector3d> inliers;
  for (const auto& p : candidates) {
    if (std::abs(best->Distance(p)) < options.inlier_distance) inliers.push_back(p);
  }
  if (inliers.size() < 3) return std::nullopt;
  GroundPlane refined = PlaneThrough(inliers);
  if (refined.normal.z() < min_normal_z) refined = *best;
  refined.inliers = 0;
  for (const auto& p : candidates) refined.inliers += std::abs(refined.Distance(p)) < options.inlier_distance ? 1 : 0;
  return refined;
}

PointCloud DownsampleGround(const PointCloud& cloud, const GroundPlane& plane, double keep_fraction, double distance) {
  if (!(keep_fraction >= 0.0 && keep_fraction <= 1.0)) {
    throw std::invalid_argument("DownsampleGround: keep_fraction must be in 0..1, not " +
                                std::to_string(keep_fraction));
  }
  PointCloud out;
  std::size_t ground_seen = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (std::abs(plane.Distance(cloud.points[i])) > distance) {
      out.Add(cloud.points[i], cloud.covariances[i]);
      continue;
    }
    // Keep the k-th ground point when k * fraction passes a whole number: exactly the fraction,
    // spread evenly, and the same every time.
    const auto before = static_cast<long long>(std::floor(static_cast<double>(ground_seen) * keep_fraction));
    const auto after = static_cast<long long>(std::floor(static_cast<double>(ground_seen + 1) * keep_fraction));
    ++ground_seen;
    if (after > before) out.Add(cloud.points[i], cloud.covariances[i]);
  }
  return out;
}

}  // namespace trimbot::perception
