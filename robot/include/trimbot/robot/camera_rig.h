#pragma once
// Calibration of the camera ring, read from and written to Kalibr's camchain format (pinhole
// camera, radtan distortion, T_cn_cnm1 chaining each camera to the previous one), so the real
// robot's calibration loads the same way as the nominal one. Kalibr does not say where the ring
// sits on the robot: cam0's pose in base_link comes from the URDF.
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace trimbot::robot {

// Pinhole camera with radial-tangential (Brown-Conrady, k1 k2 p1 p2) distortion, OpenCV/Kalibr
// conventions: pixel (0,0) is the centre of the top-left pixel.
struct PinholeRadtan {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;

  // Normalized image coordinates (x/z, y/z) -> distorted normalized coordinates.
  Eigen::Vector2d Distort(const Eigen::Vector2d& undistorted) const;
  // Distorted pixel -> undistorted normalized coordinates (Newton iterations on Distort).
  Eigen::Vector2d Undistort(const Eigen::Vector2d& pixel) const;
  // Point in the optical frame (z forward) -> pixel. Only meaningful for z > 0.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_camera) const;
  double HorizontalFovDegrees() const;
};

struct CameraCalibration {
  int index = -1;
  std::string name;      // "cam0" ...
  std::string rostopic;  // kept so a written file round-trips
  PinholeRadtan intrinsics;
  Eigen::Isometry3d T_base_camera = Eigen::Isometry3d::Identity();  // optical frame in base_link
};

struct StereoPair {
  int left = -1;  // camera indices
  int right = -1;
  double baseline = 0.0;  // m
};

class CameraRig {
 public:
  // Throws InputError naming the file and the problem.
  static CameraRig LoadKalibr(const std::string& camchain_path, const Eigen::Isometry3d& T_base_cam0);
  std::string ToKalibrYaml() const;
  // A rig of these cameras (e.g. a perturbed copy of a loaded one); `source` names where it came from.
  static CameraRig FromCameras(std::vector<CameraCalibration> cameras, std::string source);

  const std::vector<CameraCalibration>& cameras() const { return cameras_; }
  const CameraCalibration& camera(int index) const { return cameras_.at(static_cast<size_t>(index)); }
  int size() const { return static_cast<int>(cameras_.size()); }
  // Pairs (0,1), (2,3), ...: the even camera is the left one of its pair.
  std::vector<StereoPair> StereoPairs() const;
  const std::string& source() const { return source_; }

 private:
  std::vector<CameraCalibration> cameras_;
  std::string source_;
};

}  // namespace trimbot::robot
