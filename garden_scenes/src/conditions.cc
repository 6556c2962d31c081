#include "trimbot/garden/conditions.h"

#include <algorithm>
#include <cmath>

namespace trimbot::garden {

Conditions Conditions::FromYaml(const YamlMap& map) {
  Conditions c;
  c.time_of_day = map.Double("time_of_day", c.time_of_day);
  if (c.time_of_day < 0.0 || c.time_of_day > 24.0) map.Fail("time_of_day", "must be in 0..24 hours");
  c.day_of_year = map.Int("day_of_year", c.day_of_year);
  if (c.day_of_year < 1 || c.day_of_year > 366) map.Fail("day_of_year", "must be in 1..366");
  c.shadows = map.Bool("shadows", c.shadows);
  c.growth = map.Double("growth", c.growth);
  if (c.growth < 0.0 || c.growth > 1.0) map.Fail("growth", "must be in 0..1");
  if (map.Has("wind")) {
    const YamlMap wind = map.Map("wind");
    Wind& w = c.wind;
    w.mean_speed = wind.NumberOr("mean_speed", w.mean_speed, 0.0, 40.0, "m/s");
    w.roughness_length = wind.NumberOr("roughness_length", w.roughness_length, 1e-4, 2.0, "m");
    wind.RejectUnknownKeys();
  }
  if (map.Has("clouds")) {
    const YamlMap clouds = map.Map("clouds");
    Clouds& k = c.clouds;
    k.cover = clouds.NumberOr("cover", k.cover, 0.0, 1.0);
    k.mean_shadow_duration = clouds.NumberOr("mean_shadow_duration", k.mean_shadow_duration, 1.0, 36000.0, "s");
    k.direct_transmittance = clouds.NumberOr("direct_transmittance", k.direct_transmittance, 0.0, 1.0);
    k.edge_duration = clouds.NumberOr("edge_duration", k.edge_duration, 0.0, 600.0, "s");
    clouds.RejectUnknownKeys();
  }
  map.RejectUnknownKeys();
  return c;
}

Sun SunFor(const Garden& garden, const Conditions& conditions) {
  const double declination = 23.44 * M_PI / 180.0 * std::sin(2.0 * M_PI * (284.0 + conditions.day_of_year) / 365.0);
  const double hour_angle = (conditions.time_of_day - 12.0) * 15.0 * M_PI / 180.0;
  const double lat = garden.latitude;
  const double sin_elevation =
      std::sin(lat) * std::sin(declination) + std::cos(lat) * std::cos(declination) * std::cos(hour_angle);
  Sun sun;
  sun.elevation = std::asin(std::clamp(sin_elevation, -1.0, 1.0));
  // Azimuth measured from north, clockwise (east = +90 deg).
  const double azimuth_from_north =
      std::atan2(std::sin(hour_angle), std::cos(hour_angle) * std::sin(lat) - std::tan(declination) * std::cos(lat)) +
      M_PI;
  sun.azimuth = garden.north - azimuth_from_north;
  // Below a few degrees the light is dim and red; at night only the sky light is left.
  const double height = std::max(0.0, std::sin(sun.elevation));
  sun.intensity = 0.85 * std::pow(height, 0.4);
  const double warmth = std::exp(-8.0 * height);  // 1 at the horizon, ~0 at noon
  sun.colour = Eigen::Vector3d(1.0, 0.96 - 0.25 * warmth, 0.90 - 0.45 * warmth);
  sun.ambient = Eigen::Vector3d(0.30, 0.32, 0.36) * (0.35 + 0.65 * std::pow(height, 0.3));
  sun.shadows = conditions.shadows;
  sun.elevation = std::max(sun.elevation, 2.0 * M_PI / 180.0);  // keep the light above the ground
  return sun;
}

}  // namespace trimbot::garden
