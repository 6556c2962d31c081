#pragma once
// Conditions of a run: when it happens (the sun) and how far the plants have grown since they were
// trimmed. Chosen per scenario, so a map made in the morning can be tested in the evening.
#include <Eigen/Core>

#include "trimbot/common/yaml_reader.h"
#include "trimbot/garden/garden.h"

namespace trimbot::garden {

struct Conditions {
  double time_of_day = 14.0;  // h, local solar time
  int day_of_year = 250;      // early September, when the real evaluation ran
  bool shadows = true;
  double growth = 0.0;  // 0: freshly trimmed .. 1: a season's growth (up to ~15 cm, irregular)

  // Reads a `conditions:` map (all keys optional); unknown keys are errors.
  static Conditions FromYaml(const YamlMap& map);
};

struct Sun {
  double azimuth = 0.0;    // rad in the map frame: the direction the light comes from, CCW from +x
  double elevation = 0.0;  // rad above the horizon
  double intensity = 0.0;  // diffuse, 0..1
  Eigen::Vector3d colour = Eigen::Vector3d::Ones();
  Eigen::Vector3d ambient = Eigen::Vector3d::Constant(0.3);  // sky light
  bool shadows = true;
};

// Solar position for the garden's latitude and north, the day and the hour (standard declination
// and hour-angle formulas); intensity and colour follow the elevation (warmer, dimmer when low).
Sun SunFor(const Garden& garden, const Conditions& conditions);

// How far a growth value pushes foliage past its trimmed shape, at most.
constexpr double kMaxGrowth = 0.15;  // m

}  // namespace trimbot::garden
