#pragma once
// Conditions of a run: when it happens (the sun) and how far the plants have grown since they were
// trimmed. Chosen per scenario, so a map made in the morning can be tested in the evening.
#include <Eigen/Core>

#include "trimbot/common/yaml_reader.h"
#include "trimbot/garden/garden.h"

namespace trimbot::garden {

// Wind over the garden: a seeded gust process around an hourly mean (sim/weather.h turns it into
// the sway and flutter of the plants; its gust spread follows from the roughness, EN 1991-1-4).
// Default mean: a September afternoon at KNMI De Bilt, ~3.5 m/s at 10 m (KNMI climate normals;
// daily mean ~3 m/s, higher by day). 0 turns the wind off.
struct Wind {
  double mean_speed = 3.5;        // m/s, hourly mean at 10 m over open grass (as a weather station measures)
  double roughness_length = 0.1;  // m, of the garden and its surroundings (Wieringa: open land with hedges)
};

// Cumulus clouds drifting over the sun: seeded shadow passages dim the sun's direct light (its
// shadows fade with it); the sky light stays. Defaults: the Netherlands in September, 143 h of
// sunshine of ~390 h possible (KNMI normals) -> the sun is behind a cloud 63 % of the daytime;
// cumulus of optical depth >= 10 pass ~0-5 % of the direct beam; chords of 0.3-1 km drifting at
// 5-15 m/s shade a point for ~20 s to 3 min; a 1 km cloud base's penumbra plus the cloud's soft
// edge take a few seconds to pass. 0 cover turns the clouds off.
struct Clouds {
  double cover = 0.63;                 // fraction of the time the sun is behind a cloud (0: clear sky)
  double mean_shadow_duration = 60.0;  // s, a cloud's shadow passing (chord / cloud speed)
  double direct_transmittance = 0.05;  // of the sun's direct beam through a cloud
  double edge_duration = 5.0;          // s, the light's ramp at a cloud's edge
};

struct Conditions {
  double time_of_day = 14.0;  // h, local solar time
  int day_of_year = 250;      // early September, when the real evaluation ran
  bool shadows = true;
  double growth = 0.0;  // 0: freshly trimmed .. 1: a season's growth (up to ~15 cm, irregular)
  Wind wind;
  Clouds clouds;

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
