#pragma once
// Register's ICP baselines, by Open3D (point-to-point, point-to-plane, generalized ICP): kept in
// one translation unit because Open3D's headers are heavy.
#include <Eigen/Geometry>

#include "trimbot/perception/registration.h"

namespace trimbot::perception {

// `target` and `source` are usable points only (Register cleaned them). Coarse to fine: the
// correspondence distance starts at `start_distance` and halves per stage down to 3 point spacings;
// options.max_iterations is shared among the stages. Register starts it at the target's RMS radius
// (a misalignment smaller than the cloud itself is within reach): started at DUGMA's annealing
// spread (0.44 m on the benchmark's garden scene, 20 deg and 0.5 m off), generalized ICP ended 26
// deg off.
RegistrationResult Open3dIcp(const PointCloud& target, const PointCloud& source, const Eigen::Isometry3d& initial,
                             const RegistrationOptions& options, double start_distance, double point_spacing);

}  // namespace trimbot::perception
