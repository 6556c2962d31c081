#pragma once
// Synthetic garden-like point clouds with known transforms and noise, for the registration tests
// and benchmarks (which must not depend on data outside the repository).
#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "trimbot/perception/point_cloud.h"

namespace trimbot::perception {

// A patch of ground with a few bushes (spheres) and a box: structure in all three axes, as a
// registration needs. Points come with isotropic or ray-elongated (stereo-like) covariances.
inline PointCloud GardenScene(int points, std::uint32_t seed, bool anisotropic) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Eigen::Vector3d bushes[] = {{1.0, 0.5, 0.35}, {-0.8, 1.2, 0.3}, {0.3, -1.1, 0.4}};
  PointCloud cloud;
  for (int n = 0; n < points; ++n) {
    Eigen::Vector3d p;
    const double kind = u(rng);
    if (kind < 0.4) {
      p = {4.0 * u(rng) - 2.0, 4.0 * u(rng) - 2.0, 0.0};
    } else if (kind < 0.85) {
      const Eigen::Vector3d& c = bushes[static_cast<int>(u(rng) * 3) % 3];
      const double z = 2.0 * u(rng) - 1.0, a = 2.0 * M_PI * u(rng);
      p = c + c.z() * Eigen::Vector3d(std::sqrt(1 - z * z) * std::cos(a), std::sqrt(1 - z * z) * std::sin(a), z);
    } else {  // a box 0.6 x 0.4 x 0.5 at (-1, -1): its +x face and top
      p = u(rng) < 0.5 ? Eigen::Vector3d(-0.7, -1.2 + 0.4 * u(rng), 0.5 * u(rng))
                       : Eigen::Vector3d(-1.3 + 0.6 * u(rng), -1.2 + 0.4 * u(rng), 0.5);
    }
    Eigen::Matrix3d c = 1e-4 * Eigen::Matrix3d::Identity();  // 1 cm
    if (anisotropic) {
      // Depth along the ray from a sensor at (-3, 0, 1) is 5x less certain than across it.
      const Eigen::Vector3d ray = (p - Eigen::Vector3d(-3, 0, 1)).normalized();
      c = 4e-5 * Eigen::Matrix3d::Identity() + 1e-3 * ray * ray.transpose();
    }
    cloud.Add(p, c);
  }
  return cloud;
}

// Y = truth^-1 * (points of X drawn again, with noise from their covariances).
inline PointCloud ObservedFrom(const PointCloud& x, const Eigen::Isometry3d& truth, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  PointCloud y;
  const Eigen::Isometry3d inverse = truth.inverse();
  for (std::size_t i = 0; i < x.size(); i += 2) {  // half the points: not the same samples
    const Eigen::Matrix3d L = x.covariances[i].llt().matrixL();
    const Eigen::Vector3d noisy = x.points[i] + L * Eigen::Vector3d(n(rng), n(rng), n(rng));
    y.Add(inverse * noisy, inverse.linear() * x.covariances[i] * inverse.linear().transpose());
  }
  return y;
}

inline Eigen::Isometry3d Transform(double yaw_deg, double roll_deg, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(roll_deg * M_PI / 180, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = t;
  return T;
}

}  // namespace trimbot::perception
