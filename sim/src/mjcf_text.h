#pragma once
// Numbers and poses as the MJCF writers (robot_mjcf, world_builder) print them.
#include <Eigen/Geometry>

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

namespace trimbot::sim::mjcf {

inline std::string Num(double v) {
  std::ostringstream s;
  s << std::setprecision(10) << (std::abs(v) < 1e-15 ? 0.0 : v);
  return s.str();
}

inline std::string Vec(const Eigen::Vector3d& v) { return Num(v.x()) + " " + Num(v.y()) + " " + Num(v.z()); }

inline std::string PoseAttributes(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.rotation());
  return "pos=\"" + Vec(pose.translation()) + "\" quat=\"" + Num(q.w()) + " " + Num(q.x()) + " " + Num(q.y()) + " " +
         Num(q.z()) + "\"";
}

}  // namespace trimbot::sim::mjcf
