#pragma once
// A registration data set with known truth rendered from the twin (issue 16): pairs of depth views
// of the garden's bushes and objects from two viewpoints around them, back-projected into clouds in
// each camera's frame with a Kinect-like noise model (axial sigma 1.2 mm + 1.9 mm (z - 0.4 m)^2,
// lateral 0.8 px; Nguyen et al. 2012) and the matching per-point covariances; the truth is the
// relative pose of the two cameras. Written in the DUGMA data set's format for `trimbot register`.
#include <cstdint>
#include <string>
#include <vector>

#include "evaluation/registration_pair_file.h"
#include "loop/setting.h"

namespace trimbot::scenarios {

struct RegistrationSetOptions {
  std::string garden = "test_lawn";
  int pairs = 50;
  std::uint64_t seed = 1;
  double min_distance = 1.2, max_distance = 2.2;    // m from the object's centre to the camera
  double min_turn_deg = 10.0, max_turn_deg = 40.0;  // between the two viewpoints, about the object
  int stride = 4;                                   // every stride-th pixel in each direction
  double max_depth = 4.0;                           // m: farther pixels are left out (the Kinect's range)
  // Each cloud keeps the object and the ground around it, as the DUGMA data set's clouds do (each
  // a ~1.4 m square around a bush): points horizontally within the object's half-diagonal plus this
  // margin of its centre. < 0 keeps the whole view (background, far ground, other objects).
  double crop_margin = 0.5;
};

// Throws InputError naming the garden when it has no bush or object to look at.
std::vector<RegistrationPair> RenderRegistrationPairs(const RegistrationSetOptions& options, const ProjectPaths& paths,
                                                      const std::string& work_dir);

}  // namespace trimbot::scenarios
