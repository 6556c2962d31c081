#pragma once
// Where the project's data lives, and a run's setting - the one description of where and when a
// run happens, read alike from scenarios and drive plans - turned into a simulator configuration in
// one place. ("World" is kept for the simulated MuJoCo world the setting is composed into.)
#include <cstdint>
#include <string>

#include "trimbot/common/yaml_reader.h"
#include "trimbot/garden/conditions.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {

// The project's data files (robot description, calibration, gardens). Defaults to the source tree
// the binary was built from; --data-root or TRIMBOT_DATA_ROOT points elsewhere.
struct ProjectPaths {
  std::string root;

  std::string robot_dir() const { return root + "/robot"; }
  robot::RobotFiles robot_files() const { return robot::RobotFiles::InFolder(robot_dir()); }
  std::string gardens_dir() const { return root + "/garden_scenes/gardens"; }

  static ProjectPaths Default();
};

// The setting of a run: which garden, where the robot really stands at the start, the conditions,
// and the seed of the run's noise, faults and dynamics.
struct Setting {
  std::string garden;             // name in garden_scenes/gardens/ or a file
  Pose2 start;                    // true start pose of base_link (map frame)
  garden::Conditions conditions;  // time of day, season, growth
  std::uint64_t seed = 0;
  std::string source;  // the file it was read from, for errors

  // Reads `garden`, `start`, `conditions` (and `seed` when `with_seed`) from a scenario or plan.
  static Setting Read(const YamlMap& root, bool with_seed);
};

// A `seed:` key of `map`: a whole number, not negative (InputError naming the file otherwise);
// `fallback` when the key is absent.
std::uint64_t ReadSeed(const YamlMap& map, std::uint64_t fallback);

// The garden file of `setting`; an unknown garden is an error naming the scenario or plan's key.
std::string ResolveGarden(const Setting& setting, const ProjectPaths& paths);
// The garden of `setting`, read from its file.
garden::Garden LoadGarden(const Setting& setting, const ProjectPaths& paths);

// The simulator configuration for `setting` in `garden` (the setting's, read once by the caller)
// with the project's robot, composing its MuJoCo world in `world_dir`; rendering, noise and faults
// at their defaults for the caller to set.
sim::SimulatorConfig MakeSimulatorConfig(const ProjectPaths& paths, const Setting& setting, garden::Garden garden,
                                         const std::string& world_dir);

}  // namespace trimbot::scenarios
