#pragma once
// Trajectories in the TUM format ("t x y z qx qy qz qw" per line), which evo and the TUM RGB-D
// benchmark tools read: how the evaluation records true and estimated poses.
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace trimbot::scenarios {

struct StampedPose {
  double stamp = 0.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
};

// One pose as a TUM line (with its newline).
std::string TumLine(double stamp, const Eigen::Isometry3d& pose);

// The poses of a TUM file, in its order ('#' lines and blank lines skipped). InputError naming the
// file and the line for anything but 8 finite numbers a line.
std::vector<StampedPose> ReadTum(const std::string& path);

}  // namespace trimbot::scenarios
