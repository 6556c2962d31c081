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
