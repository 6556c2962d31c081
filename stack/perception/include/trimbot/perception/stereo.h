#pragma once
// Stereo depth from the camera ring with per-point uncertainty.
//
// Each pair (cameras 2k, 2k+1, the even one on the left) is rectified from its calibration
// (radtan distortion, relative pose), matched with semi-global matching, and every disparity
// becomes a 3D point in base_link with the covariance propagated from the pixel and disparity
// noise: depth variance grows with Z^4 (Z = f B / d). The ring's five pairs together give a
// 360-degree cloud. Ground handling (plane fit, thinning) needs no labels.
#include <opencv2/core.hpp>

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "trimbot/messages/sensor_messages.h"
#include "trimbot/perception/point_cloud.h"
#include "trimbot/robot/camera_rig.h"

namespace trimbot::perception {

struct StereoOptions {
  // Matching. The robot's FPGA runs SGM with 32 disparities: with the rectified f B of 15 px m
  // (f 499 px, B 3 cm) that covers depths from 0.5 m outwards.
  int disparities = 32;
  int block_size = 5;  // px, odd
  // Quality mode: 64 disparities (from 0.25 m) and full 8-path SGM; otherwise OpenCV's 3-way SGM,
  // which is multithreaded and about ten times faster.
  bool dense = false;
  int uniqueness_ratio = 10;          // %: the best cost must beat the second best by this much
  int speckle_window = 100;           // px: smaller blobs of consistent disparity are dropped
  int speckle_range = 2;              // px: disparity step that splits a blob
  int max_left_right_difference = 1;  // px, left-right consistency check
  // Pixels whose neighbourhood (texture_window px square) has a mean horizontal gradient below
  // min_texture (grey levels per px) get no estimate (0 switches this off). On the blank sky SGM
  // matches image noise: in the rendered test lawn a quarter of all estimates were such phantom points
  // at 0.5..8 m; the threshold removes them (and distant, blurred lawn with them).
  double min_texture = 0.9;
  int texture_window = 15;  // px, odd
  // Noise of the measurements the cloud is built from.
  double disparity_sigma = 0.25;  // px
  double pixel_sigma = 0.5;       // px, of u and v (pixel quantization)
  // Cloud: points outside [min_depth, max_depth] (m, along the rectified optical axis) are
  // dropped, and only every `stride`-th pixel in u and v is used.
  double min_depth = 0.3;
  double max_depth = 8.0;
  int stride = 1;

  int EffectiveDisparities() const { return dense ? 64 : disparities; }
};

// Rectification of one stereo pair of the rig: both images are resampled into a common pinhole
// camera (no distortion, rows aligned, same principal point), so a scene point appears on the
// same row in both and its disparity is f B / Z.
class StereoRectifier {
 public:
  // Throws InputError(rig.source(), ...) if a camera of `pair` is not in the rig, and
  // std::invalid_argument if the cameras differ in resolution.
  StereoRectifier(const robot::CameraRig& rig, const robot::StereoPair& pair);

  struct RectifiedPair {
    cv::Mat left, right;  // CV_8U grey, image_size()
  };
  // Accepts CV_8UC3 (RGB) or CV_8UC1 images of the calibrated size; std::invalid_argument otherwise.
  RectifiedPair Rectify(const cv::Mat& left, const cv::Mat& right) const;

  const robot::StereoPair& pair() const { return pair_; }
  double focal_length() const { return focal_length_; }                 // px, rectified
  double baseline() const { return baseline_; }                         // m
  Eigen::Vector2d principal_point() const { return principal_point_; }  // px, rectified (both images)
  cv::Size image_size() const { return image_size_; }
  // Pose of the rectified left optical frame (z forward, x right, y down) in base_link.
  const Eigen::Isometry3d& T_base_rectified_left() const { return T_base_rectified_left_; }
  // Rotation from the original left optical frame into the rectified left optical frame.
  const Eigen::Matrix3d& R_rectified_left() const { return R_rectified_left_; }
  // For each rectified left pixel, the pixel of the original (distorted) left image it samples
  // (CV_32F each); used to carry ground truth of the original image into the rectified frame.
  const cv::Mat& left_map_x() const { return left_map_x_; }
  const cv::Mat& left_map_y() const { return left_map_y_; }
  const robot::PinholeRadtan& left_camera() const { return left_camera_; }

 private:
  robot::StereoPair pair_;
  robot::PinholeRadtan left_camera_;
  cv::Size image_size_;
  double focal_length_ = 0.0;
  double baseline_ = 0.0;
  Eigen::Vector2d principal_point_ = Eigen::Vector2d::Zero();
  Eigen::Isometry3d T_base_rectified_left_ = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R_rectified_left_ = Eigen::Matrix3d::Identity();
  cv::Mat left_map_x_, left_map_y_;
  // Fixed-point versions of both maps: cv::remap is about twice as fast with them.
  cv::Mat left_map_fixed_, left_map_interpolation_, right_map_fixed_, right_map_interpolation_;
};

// Semi-global matching (cv::StereoSGBM) on rectified grey images.
class StereoMatcher {
 public:
  explicit StereoMatcher(const StereoOptions& options = {});
  ~StereoMatcher();
  StereoMatcher(StereoMatcher&&) noexcept;
  StereoMatcher& operator=(StereoMatcher&&) noexcept;

  // Disparity of the left image in px (CV_32F, 1/16 px steps), NaN where there is no estimate.
  // std::invalid_argument if the images are not CV_8UC1 of the same size.
  cv::Mat Compute(const cv::Mat& left_rectified, const cv::Mat& right_rectified) const;
  const StereoOptions& options() const { return options_; }

 private:
  StereoOptions options_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Points of a rectified disparity image in base_link with their covariances
// J diag(sigma_u^2, sigma_v^2, sigma_d^2) J^T, J = d(X,Y,Z)/d(u,v,d), rotated into base_link.
// Uses options.min_depth, max_depth, stride, pixel_sigma and disparity_sigma.
PointCloud DisparityToCloud(const cv::Mat& disparity, const StereoRectifier& rectifier,
                            const StereoOptions& options = {});

// An image message as a cv::Mat sharing nothing with it (CV_8UC3 RGB or CV_8UC1).
// std::invalid_argument for an unknown encoding or a data size that does not match.
cv::Mat ImageToMat(const messages::Image& image);

// The whole ring: rectifiers for every pair of the rig (built once) and one matcher.
class RingStereo {
 public:
  RingStereo(const robot::CameraRig& rig, const StereoOptions& options = {});

  struct PairResult {
    cv::Mat disparity;  // rectified left, px (see StereoMatcher::Compute)
    PointCloud cloud;   // base_link
  };
  // One pair of the frame. std::invalid_argument naming the camera if its image is missing.
  PairResult ComputePair(const messages::RingFrame& frame, int pair_index) const;
  // All pairs merged into one 360-degree cloud in base_link.
  PointCloud RingCloud(const messages::RingFrame& frame) const;
  // The same into `cloud`, replacing its points but keeping its memory: a full-resolution ring
  // cloud is about 70 MB, and touching fresh memory every frame costs more than the matching.
  void RingCloud(const messages::RingFrame& frame, PointCloud* cloud) const;

  const std::vector<StereoRectifier>& rectifiers() const { return rectifiers_; }
  const StereoMatcher& matcher() const { return matcher_; }
  const StereoOptions& options() const { return options_; }

 private:
  cv::Mat PairDisparity(const messages::RingFrame& frame, int pair_index) const;

  StereoOptions options_;
  std::vector<StereoRectifier> rectifiers_;
  StereoMatcher matcher_;
};

// One-shot convenience: builds a RingStereo (rectification maps included) for one frame.
PointCloud RingCloud(const messages::RingFrame& frame, const robot::CameraRig& rig, const StereoOptions& options = {});

// Ground plane n . p + offset = 0 in the cloud's frame, n pointing up (n.z > 0).
struct GroundPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
  int inliers = 0;
  double Distance(const Eigen::Vector3d& point) const { return normal.dot(point) + offset; }
};

struct GroundFitOptions {
  double candidate_height = 0.3;  // m: only points with |z| below this (base_link) are tried
  double inlier_distance = 0.05;  // m
  int iterations = 200;
  std::uint64_t seed = 1;
  double max_tilt_degrees = 20.0;  // planes steeper than this are not ground
};

// RANSAC on the low points of a cloud in base_link, refined by least squares on the inliers.
// Deterministic for a given seed. nullopt if fewer than 3 candidate points or no plane fits.
std::optional<GroundPlane> FitGroundPlane(const PointCloud& cloud, const GroundFitOptions& options = {});

// All points farther than `distance` (m) from the plane, and `keep_fraction` (0..1) of those
// closer, evenly spread through the cloud's order. std::invalid_argument for a fraction outside 0..1.
PointCloud DownsampleGround(const PointCloud& cloud, const GroundPlane& plane, double keep_fraction, double distance);

}  // namespace trimbot::perception
