#include "evaluation/tum_trajectory.h"

#include <iomanip>
#include <sstream>

namespace trimbot::scenarios {

std::string TumLine(double stamp, const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.rotation());
  std::ostringstream line;
  line << std::fixed << std::setprecision(6) << stamp << ' ' << pose.translation().x() << ' ' << pose.translation().y()
       << ' ' << pose.translation().z() << ' ' << std::setprecision(9) << q.x() << ' ' << q.y() << ' ' << q.z() << ' '
       << q.w() << '\n';
  return line.str();
}

}  // namespace trimbot::scenarios
