#include "loop/world_setup.h"

#include <cmath>
#include <cstdlib>

#include "trimbot/common/input_error.h"
#include "trimbot/common/yaml_reader.h"
#include "trimbot/garden/garden.h"

namespace trimbot::scenarios {

ProjectPaths ProjectPaths::Default() {
  if (const char* env = std::getenv("TRIMBOT_DATA_ROOT")) return {env};
  return {TRIMBOT_SOURCE_DIR};
}

WorldSetup WorldSetup::Read(const YamlMap& root, bool with_seed) {
  WorldSetup world;
  world.source = root.file();
  world.garden = root.String("garden");
  const YamlMap start = root.Map("start");
  world.start.x = start.Number("x", -1e4, 1e4, "m");
  world.start.y = start.Number("y", -1e4, 1e4, "m");
  world.start.yaw = start.NumberOr("yaw_deg", 0.0, -360.0, 360.0, "deg") * M_PI / 180.0;
  start.RejectUnknownKeys();
  if (root.Has("conditions")) world.conditions = garden::Conditions::FromYaml(root.Map("conditions"));
  if (with_seed) {
    const int seed = root.Int("seed", 1);
    if (seed < 0) root.Fail("seed", "must not be negative");
    world.seed = static_cast<std::uint64_t>(seed);
  }
  return world;
}

std::string ResolveGarden(const WorldSetup& world, const ProjectPaths& paths) {
  try {
    return garden::Garden::Resolve(world.garden, paths.gardens_dir());
  } catch (const InputError& e) {
    if (world.source.empty()) throw;
    throw InputError(world.source, "key 'garden': " + e.problem());
  }
}

sim::SimulatorConfig MakeSimulatorConfig(const ProjectPaths& paths, const WorldSetup& world,
                                         const std::string& world_dir) {
  sim::SimulatorConfig config;
  config.robot = paths.robot_files();
  config.garden_path = ResolveGarden(world, paths);
  config.world_dir = world_dir;
  config.seed = world.seed;
  config.start = world.start;
  config.conditions = world.conditions;
  return config;
}

}  // namespace trimbot::scenarios
