#pragma once
// `trimbot stereo`: one rendered ring frame through the stack's stereo (all five pairs), with the
// errors of each pair's disparity against the renderer's ground truth, disparity images and the
// merged 360-degree cloud.
#include <cstdint>
#include <string>

#include "loop/setting.h"

namespace trimbot::scenarios {

struct StereoFrameOptions {
  std::string garden;  // name or file
  std::string output;  // folder
  bool dense = false;  // 64 disparities, 8-path SGM instead of the robot's 32
  std::uint64_t seed = 1;
  double x = 0.0, y = 0.0, yaw_degrees = 0.0;  // the robot in the map
  int stride = 2;                              // every n-th pixel into the cloud
};

// Prints the errors per pair and writes the images and ring_cloud.ply; returns the exit code.
int RunStereoFrame(const StereoFrameOptions& options, const ProjectPaths& paths);

}  // namespace trimbot::scenarios
