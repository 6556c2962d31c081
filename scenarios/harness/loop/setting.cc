#include "loop/setting.h"

#include <cmath>
#include <cstdlib>
#include <utility>

#include "trimbot/common/input_error.h"
#include "trimbot/common/yaml_reader.h"
#include "trimbot/garden/garden.h"

namespace trimbot::scenarios {

ProjectPaths ProjectPaths::Default() {
  if (const char* env = std::getenv("TRIMBOT_DATA_ROOT")) return {env};
  return {TRIMBOT_SOURCE_DIR};
}

Setting Setting::Read(const YamlMap& root, bool with_seed) {
  Setting setting;
  setting.source = root.file();
  setting.garden = root.String("garden");
  const YamlMap start = root.Map("start");
  setting.start.x = start.Number("x", -1e4, 1e4, "m");
  setting.start.y = start.Number("y", -1e4, 1e4, "m");
  setting.start.yaw = start.NumberOr("yaw_deg", 0.0, -360.0, 360.0, "deg") * M_PI / 180.0;
  start.RejectUnknownKeys();
  if (root.Has("conditions")) setting.conditions = garden::Conditions::FromYaml(root.Map("conditions"));
  if (with_seed) setting.seed = ReadSeed(root, 1);
  return setting;
}

std::uint64_t ReadSeed(const YamlMap& map, std::uint64_t fallback) {
  if (!map.Has("seed")) return fallback;
  const int seed = map.Int("seed");
  if (seed < 0) map.Fail("seed", "must not be negative");
  return static_cast<std::uint64_t>(seed);
}

std::string ResolveGarden(const Setting& setting, const ProjectPaths& paths) {
  try {
    return garden::Garden::Resolve(setting.garden, paths.gardens_dir());
  } catch (const InputError& e) {
    if (setting.source.empty()) throw;
    throw InputError(setting.source, "key 'garden': " + e.problem());
  }
}

garden::Garden LoadGarden(const Setting& setting, const ProjectPaths& paths) {
  return garden::Garden::Load(ResolveGarden(setting, paths));
}

sim::SimulatorConfig MakeSimulatorConfig(const ProjectPaths& paths, const Setting& setting, garden::Garden garden,
                                         const std::string& world_dir) {
  sim::SimulatorConfig config;
  config.robot = paths.robot_files();
  config.garden = std::move(garden);
  config.world_dir = world_dir;
  config.seed = setting.seed;
  config.start = setting.start;
  config.conditions = setting.conditions;
  return config;
}

}  // namespace trimbot::scenarios
