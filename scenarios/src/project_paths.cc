#include "project_paths.h"

#include <cstdlib>

#include "trimbot/garden/garden.h"

namespace trimbot::scenarios {

ProjectPaths ProjectPaths::Default() {
  if (const char* env = std::getenv("TRIMBOT_DATA_ROOT")) return {env};
  return {TRIMBOT_SOURCE_DIR};
}

sim::SimulatorConfig ProjectPaths::SimulatorConfigFor(const std::string& garden, const std::string& world_dir) const {
  sim::SimulatorConfig config;
  config.urdf_path = urdf();
  config.calibration_path = nominal_calibration();
  config.robot_parameters_path = robot_parameters();
  config.garden_path = garden::Garden::Resolve(garden, gardens_dir());
  config.world_dir = world_dir;
  return config;
}

}  // namespace trimbot::scenarios
