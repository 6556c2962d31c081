#pragma once
// A simulator configured for a test.
#include "test_support.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::testing {

inline sim::SimulatorConfig TestConfig(const std::string& garden_file, const std::string& world_name,
                                       bool cameras = false) {
  sim::SimulatorConfig config;
  config.robot = robot::RobotFiles::InFolder(SourcePath("robot"));
  config.garden = garden::Garden::Load(garden_file);
  config.world_dir = TempDir(world_name);
  config.seed = 1;
  config.render_cameras = cameras;
  return config;
}

inline std::string TestLawn() { return SourcePath("garden_scenes/gardens/test_lawn.yaml"); }

}  // namespace trimbot::testing
