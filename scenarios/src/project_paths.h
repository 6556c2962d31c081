#pragma once
// Where the project's data files live (robot description, calibration, gardens). Defaults to the
// source tree the binary was built from; --data-root points elsewhere (e.g. an installed copy).
#include <string>

#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {

struct ProjectPaths {
  std::string root;

  std::string urdf() const { return root + "/robot/urdf/trimbot.urdf"; }
  std::string nominal_calibration() const { return root + "/robot/calibration/nominal_camchain.yaml"; }
  std::string robot_parameters() const { return root + "/robot/config/robot_parameters.yaml"; }
  std::string gardens_dir() const { return root + "/garden_scenes/gardens"; }

  static ProjectPaths Default();

  // A simulator configuration with the project's robot (URDF, nominal calibration, parameters)
  // in `garden` (name or file), composing its world in `world_dir`; the rest at defaults.
  sim::SimulatorConfig SimulatorConfigFor(const std::string& garden, const std::string& world_dir) const;
};

}  // namespace trimbot::scenarios
