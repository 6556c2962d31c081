#include "trimbot/perception/local_fusion.h"

#include <chrono>

namespace trimbot::perception {
namespace {

StereoOptions StrideOptions(int stride) {
  StereoOptions options;
  options.stride = stride;
  return options;
}

}  // namespace

LocalFusion::LocalFusion(const robot::CameraRig& rig, const LocalFusionOptions& options)
    : options_(options), stereo_(rig, StrideOptions(options.stride)) {}

bool LocalFusion::Wants(double stamp) const { return options_.enabled && stamp + 1e-9 >= next_stamp_; }

std::optional<CloudRegistration> LocalFusion::Add(const messages::RingFrame& frame,
                                                  const Eigen::Isometry3d& T_odom_base) {
  next_stamp_ = frame.stamp + options_.interval;
  Keyframe current{frame.stamp, stereo_.RingCloud(frame), T_odom_base};
  if (const auto ground = FitGroundPlane(current.cloud)) {
    current.cloud = DownsampleGround(current.cloud, *ground, options_.ground_keep, 0.05);
  }
  std::optional<CloudRegistration> out;
  if (previous_ && !current.cloud.empty() && !previous_->cloud.empty()) {
    CloudRegistration r;
    r.previous_stamp = previous_->stamp;
    r.stamp = current.stamp;
    r.previous_points = previous_->cloud.size();
    r.points = current.cloud.size();
    r.odometry_guess = previous_->T_odom_base.inverse() * current.T_odom_base;
    const auto start = std::chrono::steady_clock::now();
    r.registration = Register(previous_->cloud, current.cloud, r.odometry_guess);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    out = std::move(r);
  }
  previous_ = std::move(current);
  return out;
}

}  // namespace trimbot::perception
