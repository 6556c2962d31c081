#pragma once
// Register's ICP baselines, by Open3D (point-to-point, point-to-plane, generalized ICP): kept in
// one translation unit because Open3D's headers are heavy.
#include <Eigen/Geometry>

#include "trimbot/perception/registration.h"

namespace trimbot::perception {

// `target` and `source` are usable points only (Register cleaned them). Coarse to fine: the
// correspondence distance starts at the target's RMS radius and halves per stage down to 3 point
// spacings; options.max_iterations is shared among the stages.
RegistrationResult Open3dIcp(const PointCloud& target, const PointCloud& source, const Eigen::Isometry3d& initial,
                             const RegistrationOptions& options, double point_spacing);

}  // namespace trimbot::perception
