#pragma once
// The registration pair file (the DUGMA data set's format, which `trimbot register` reads and
// `trimbot register-set` writes): optional `covariances metric|relative`, `R r00 .. r22` and
// `t tx ty tz` (ground truth x = R y + t), then blocks `X n` and `Y m` of lines
// `x y z c00 c01 c02 c11 c12 c22`; `#` starts a comment.
#include <Eigen/Geometry>
#include <string>

#include "trimbot/perception/point_cloud.h"
#include "trimbot/perception/registration.h"

namespace trimbot::scenarios {

// Two clouds and the truth that maps the second onto the first: x = truth * y.
struct RegistrationPair {
  std::string name;
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  perception::PointCloud x, y;
  // The DUGMA data set's covariances are relative weights; a file's line `covariances metric`
  // says they are variances in m^2 (the rendered set's).
  bool relative_covariances = true;
};

// `options` with the pair's own covariance convention.
inline perception::RegistrationOptions ForPair(perception::RegistrationOptions options, const RegistrationPair& pair) {
  options.relative_covariances = pair.relative_covariances;
  return options;
}

// Throws InputError naming the file and line: numbers must be whole tokens and finite (points may
// be NaN, the data set's mark of an unusable point), R a rotation, each header line once.
RegistrationPair LoadRegistrationPair(const std::string& path);
void WriteRegistrationPair(const std::string& path, const RegistrationPair& pair);

}  // namespace trimbot::scenarios
