#pragma once
// Local fusion: a 360-degree stereo cloud of the ring every `interval` seconds, registered to the
// previous one (DUGMA, with both clouds' per-point covariances) starting from the wheel-odometry
// guess of the relative pose. The registration refines the odometry between the two frames.
#include <Eigen/Geometry>
#include <optional>

#include "trimbot/messages/sensor_messages.h"
#include "trimbot/perception/point_cloud.h"
#include "trimbot/perception/registration.h"
#include "trimbot/perception/stereo.h"
#include "trimbot/robot/camera_rig.h"

namespace trimbot::perception {

struct LocalFusionOptions {
  bool enabled = false;
  double interval = 1.0;      // s between clouds
  int stride = 4;             // pixel stride of the stereo clouds (every pixel: ~500k points a ring)
  double ground_keep = 0.02;  // fraction of ground points kept (the lawn would dominate the fit)
};

// One registration of a cloud to the previous one. Relative poses are of the current base_link in
// the previous base_link frame.
struct CloudRegistration {
  double previous_stamp = 0.0, stamp = 0.0;
  std::size_t previous_points = 0, points = 0;
  Eigen::Isometry3d odometry_guess = Eigen::Isometry3d::Identity();
  RegistrationResult registration;
  double seconds = 0.0;  // wall-clock time of the registration
};

class LocalFusion {
 public:
  LocalFusion(const robot::CameraRig& rig, const LocalFusionOptions& options);

  // Whether a ring frame at `stamp` would be used (the component asks only for those).
  bool Wants(double stamp) const;
  // Adds a frame with the odometry pose (odom frame) at its stamp; returns the registration to the
  // previous cloud, if there was one with points.
  std::optional<CloudRegistration> Add(const messages::RingFrame& frame, const Eigen::Isometry3d& T_odom_base);

 private:
  struct Keyframe {
    double stamp = 0.0;
    PointCloud cloud;
    Eigen::Isometry3d T_odom_base = Eigen::Isometry3d::Identity();
  };
  LocalFusionOptions options_;
  RingStereo stereo_;
  std::optional<Keyframe> previous_;
  double next_stamp_ = 0.0;
};

}  // namespace trimbot::perception
