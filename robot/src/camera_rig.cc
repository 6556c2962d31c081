#include "trimbot/robot/camera_rig.h"

#include <cmath>
#include <iomanip>
#include <set>
#include <sstream>

#include "trimbot/common/input_error.h"
#include "trimbot/common/yaml_reader.h"

namespace trimbot::robot {

Eigen::Vector2d PinholeRadtan::Distort(const Eigen::Vector2d& u) const {
  const double x = u.x(), y = u.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

Eigen::Vector2d PinholeRadtan::Undistort(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d target((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  Eigen::Vector2d u = target;
  for (int iteration = 0; iteration < 50; ++iteration) {
    // Newton step with a numerical Jacobian; converges in a few steps inside the image.
    const Eigen::Vector2d residual = Distort(u) - target;
    if (residual.norm() < 1e-12) break;
    constexpr double h = 1e-7;
    Eigen::Matrix2d jacobian;
    jacobian.col(0) = (Distort(u + Eigen::Vector2d(h, 0)) - Distort(u)) / h;
    jacobian.col(1) = (Distort(u + Eigen::Vector2d(0, h)) - Distort(u)) / h;
    u -= jacobian.inverse() * residual;
  }
  return u;
}

Eigen::Vector2d PinholeRadtan::Project(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d d = Distort(Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()));
  return {fx * d.x() + cx, fy * d.y() + cy};
}

double PinholeRadtan::HorizontalFovDegrees() const {
  const double left = Undistort({-0.5, cy}).x();
  const double right = Undistort({width - 0.5, cy}).x();
  return (std::atan(right) - std::atan(left)) * 180.0 / M_PI;
}

namespace {

Eigen::Isometry3d ReadTransform(const YamlMap& cam, const std::string& key) {
  const YAML::Node rows = cam.node()[key];
  Eigen::Matrix4d m;
  bool ok = rows.IsSequence() && rows.size() == 4;
  for (int r = 0; ok && r < 4; ++r) {
    ok = rows[r].IsSequence() && rows[r].size() == 4;
    for (int c = 0; ok && c < 4; ++c) {
      try {
        m(r, c) = rows[r][c].as<double>();
      } catch (const YAML::Exception&) {
        ok = false;
      }
    }
  }
  if (!ok) cam.Fail(key, "expected a 4x4 matrix of numbers");
  if (!m.allFinite()) cam.Fail(key, "must hold finite numbers");
  if (m.topRightCorner<3, 1>().norm() > 100.0) cam.Fail(key, "translation beyond 100 m");
  const Eigen::Matrix3d rotation = m.topLeftCorner<3, 3>();
  if ((rotation * rotation.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-3 || rotation.determinant() < 0.0 ||
      m.row(3).head<3>().norm() > 1e-9 || std::abs(m(3, 3) - 1.0) > 1e-9) {
    cam.Fail(key, "not a rigid transform (rotation part is not orthonormal)");
  }
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(rotation).normalized().toRotationMatrix();
  t.translation() = m.topRightCorner<3, 1>();
  return t;
}

}  // namespace

CameraRig CameraRig::FromCameras(std::vector<CameraCalibration> cameras, std::string source) {
  CameraRig rig;
  rig.cameras_ = std::move(cameras);
  rig.source_ = std::move(source);
  return rig;
}

CameraRig CameraRig::LoadKalibr(const std::string& path, const Eigen::Isometry3d& T_base_cam0) {
  const YamlMap root = YamlMap::LoadFile(path);
  CameraRig rig;
  rig.source_ = path;
  // 'camfix' appears in the TrimBot2020 calibration and is not used by the camchain itself.
  root.Has("camfix");
  for (int index = 0;; ++index) {
    const std::string name = "cam" + std::to_string(index);
    if (!root.Has(name)) break;
    const YamlMap cam = root.Map(name);
    CameraCalibration calibration;
    calibration.index = index;
    calibration.name = name;
    if (cam.String("camera_model") != "pinhole") cam.Fail("camera_model", "only 'pinhole' is supported");
    if (cam.String("distortion_model") != "radtan") cam.Fail("distortion_model", "only 'radtan' is supported");
    const auto k = cam.Doubles("intrinsics", 4);
    const auto d = cam.Doubles("distortion_coeffs", 4);
    const auto resolution = cam.Doubles("resolution", 2);
    PinholeRadtan& in = calibration.intrinsics;
    in.fx = k[0], in.fy = k[1], in.cx = k[2], in.cy = k[3];
    in.k1 = d[0], in.k2 = d[1], in.p1 = d[2], in.p2 = d[3];
    for (double v : resolution) {
      if (v != std::floor(v) || v < 16 || v > 16384)
        cam.Fail("resolution", "must be whole pixel counts in [16, 16384]");
    }
    in.width = static_cast<int>(resolution[0]);
    in.height = static_cast<int>(resolution[1]);
    // Numbers are finite (YamlMap); a focal length under 10 px or a principal point off the image
    // is not a camera.
    if (!(in.fx >= 10.0 && in.fx <= 1e5) || !(in.fy >= 10.0 && in.fy <= 1e5)) {
      cam.Fail("intrinsics", "focal lengths must be in [10, 100000] px");
    }
    if (in.cx < 0.0 || in.cx > in.width || in.cy < 0.0 || in.cy > in.height) {
      cam.Fail("intrinsics", "the principal point must lie on the image");
    }
    for (double v : d) {
      if (std::abs(v) > 10.0) cam.Fail("distortion_coeffs", "must be in [-10, 10]");
    }
    calibration.rostopic = cam.String("rostopic", "");
    // Kalibr's keys the twin does not use are still checked: a broken value means a broken file.
    if (cam.Has("cam_overlaps")) cam.Integers("cam_overlaps", 0, 99);
    if (cam.Has("T_cam_imu")) ReadTransform(cam, "T_cam_imu");
    if (cam.Has("timeshift_cam_imu")) cam.Number("timeshift_cam_imu", -10.0, 10.0, "s");
    if (index == 0) {
      if (cam.Has("T_cn_cnm1")) cam.Fail("T_cn_cnm1", "cam0 has no previous camera");
      calibration.T_base_camera = T_base_cam0;
    } else {
      if (!cam.Has("T_cn_cnm1")) cam.Fail("T_cn_cnm1", "missing (needed for every camera after cam0)");
      const Eigen::Isometry3d T_cn_cnm1 = ReadTransform(cam, "T_cn_cnm1");
      calibration.T_base_camera = rig.cameras_.back().T_base_camera * T_cn_cnm1.inverse();
    }
    cam.RejectUnknownKeys();
    rig.cameras_.push_back(calibration);
  }
  if (rig.cameras_.empty()) throw InputError(path, "no cameras (expected keys cam0, cam1, ...)");
  root.RejectUnknownKeys();
  return rig;
}

std::string CameraRig::ToKalibrYaml() const {
  std::ostringstream out;
  out << std::setprecision(15);
  for (const auto& cam : cameras_) {
    out << cam.name << ":\n";
    if (cam.index > 0) {
      const Eigen::Matrix4d T =
          (cameras_[static_cast<size_t>(cam.index - 1)].T_base_camera.inverse() * cam.T_base_camera).inverse().matrix();
      out << "  T_cn_cnm1:\n";
      for (int r = 0; r < 4; ++r) {
        out << "  - [" << T(r, 0) << ", " << T(r, 1) << ", " << T(r, 2) << ", " << T(r, 3) << "]\n";
      }
    }
    const auto& in = cam.intrinsics;
    out << "  camera_model: pinhole\n"
        << "  distortion_coeffs: [" << in.k1 << ", " << in.k2 << ", " << in.p1 << ", " << in.p2 << "]\n"
        << "  distortion_model: radtan\n"
        << "  intrinsics: [" << in.fx << ", " << in.fy << ", " << in.cx << ", " << in.cy << "]\n"
        << "  resolution: [" << in.width << ", " << in.height << "]\n";
    if (!cam.rostopic.empty()) out << "  rostopic: " << cam.rostopic << "\n";
  }
  return out.str();
}

std::vector<StereoPair> CameraRig::StereoPairs() const {
  std::vector<StereoPair> pairs;
  for (size_t i = 0; i + 1 < cameras_.size(); i += 2) {
    const double baseline =
        (cameras_[i].T_base_camera.translation() - cameras_[i + 1].T_base_camera.translation()).norm();
    pairs.push_back({static_cast<int>(i), static_cast<int>(i + 1), baseline});
  }
  return pairs;
}

}  // namespace trimbot::robot
