#pragma once
// Trajectories in the TUM format ("t x y z qx qy qz qw" per line), which evo and the TUM RGB-D
// benchmark tools read: how the evaluation records true and estimated poses.
#include <Eigen/Geometry>
#include <string>

namespace trimbot::scenarios {

// One pose as a TUM line (with its newline).
std::string TumLine(double stamp, const Eigen::Isometry3d& pose);

}  // namespace trimbot::scenarios
