#include "evaluation/tum_trajectory.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {

std::string TumLine(double stamp, const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.rotation());
  std::ostringstream line;
  line << std::fixed << std::setprecision(6) << stamp << ' ' << pose.translation().x() << ' ' << pose.translation().y()
       << ' ' << pose.translation().z() << ' ' << std::setprecision(9) << q.x() << ' ' << q.y() << ' ' << q.z() << ' '
       << q.w() << '\n';
  return line.str();
}

std::vector<StampedPose> ReadTum(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path, "cannot open the trajectory file");
  std::vector<StampedPose> poses;
  std::string line;
  for (int line_number = 1; std::getline(file, line); ++line_number) {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream words(line);
    std::vector<double> values;
    std::string word;
    while (words >> word) {
      char* end = nullptr;
      const double value = std::strtod(word.c_str(), &end);
      if (end == word.c_str() || *end != '\0' || !std::isfinite(value)) {
        throw InputError(path, "line " + std::to_string(line_number) + ": '" + word + "' is not a finite number");
      }
      values.push_back(value);
    }
    if (values.size() != 8) {
      throw InputError(path, "line " + std::to_string(line_number) +
                                 ": expected 8 numbers \"t x y z qx qy qz qw\", got " + std::to_string(values.size()));
    }
    StampedPose pose;
    pose.stamp = values[0];
    pose.T.translation() = Eigen::Vector3d(values[1], values[2], values[3]);
    pose.T.linear() = Eigen::Quaterniond(values[7], values[4], values[5], values[6]).normalized().toRotationMatrix();
    poses.push_back(pose);
  }
  if (file.bad()) throw InputError(path, "read error");
  return poses;
}

}  // namespace trimbot::scenarios
