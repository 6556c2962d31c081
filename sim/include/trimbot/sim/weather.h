#pragma once
// The weather the cameras see: plants that move in gusty wind, and cloud shadows that dim the sun.
// Both are pure functions of (seed, time): a frame can be rendered alone, and the same seed gives
// the same sequence whatever was rendered before (the runs' determinism rests on it).
#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "trimbot/garden/conditions.h"
#include "trimbot/garden/object_class.h"

namespace trimbot::sim {

// Along-wind speed near the ground: the hourly mean carried down to height z by the log profile,
// with gusts as a sum of sinusoids whose frequencies follow the Kaimal spectrum of surface-layer
// turbulence (random phases from the seed) and whose spread is the turbulence intensity. Gusts
// travel with the mean wind (Taylor's frozen turbulence), so neighbouring plants sway in turn.
class GustyWind {
 public:
  GustyWind(const garden::Wind& wind, std::uint64_t seed);
  double MeanSpeedAt(double height) const;
  // The gust signal of unit variance at `position` (map frame, m) and time t.
  double Gust(const Eigen::Vector2d& position, double t) const;
  double SpeedAt(const Eigen::Vector2d& position, double height, double t) const;
  const Eigen::Vector2d& direction() const { return direction_; }  // unit, where the wind blows to
  const garden::Wind& wind() const { return wind_; }
  std::uint64_t seed() const { return seed_; }

  struct Component {
    double frequency;  // Hz
    double amplitude;  // of the unit-variance signal
    double phase;      // rad
  };
  const std::vector<Component>& components() const { return components_; }

 private:
  garden::Wind wind_;
  std::uint64_t seed_;
  Eigen::Vector2d direction_;
  std::vector<Component> components_;
};

// How a plant of a class answers the wind: its crown as a damped oscillator driven by the drag
// on it (whole-plant sway), its outer shoots and leaves as lighter ones (flutter). Values and
// their sources in weather.cc.
struct PlantMechanics {
  double sway_frequency = 0.0;               // Hz, natural frequency of the whole plant
  double sway_damping = 0.0;                 // damping ratio
  double crown_mass_per_area = 0.0;          // kg per m^2 of frontal area
  double drag_coefficient = 0.0;             // of the crown, reconfigured in the wind
  double flutter_amplitude_per_speed = 0.0;  // m of shoot/leaf displacement per m/s of wind
  double flutter_frequency = 0.0;            // Hz, shoots and leaves
  double flutter_wavelength = 0.0;           // m, size of the parts that move together
};
// Plants move; trunks, fences and obstacles do not (all zero).
PlantMechanics MechanicsOf(garden::ObjectClass object_class);

// The displacement of points of a plant at time t: the crown's sway, growing with the square of
// the height above the plant's base (a cantilever's first mode), plus the shoots' flutter.
class PlantMotion {
 public:
  // `base`: the plant's footprint centre on the ground (map frame); `height`: its top above it.
  PlantMotion(const GustyWind& wind, garden::ObjectClass object_class, int object_id, const Eigen::Vector3d& base,
              double height);
  Eigen::Vector3d Displacement(const Eigen::Vector3d& point, double t) const;
  // The crown top's sway along the wind at time t (m; for tests and the docs' figures).
  double Sway(double t) const;
  // A bound of |Displacement| over all points and times (for the renderer's culling).
  double MaxDisplacement() const;
  bool moves() const { return mechanics_.sway_frequency > 0.0; }

 private:
  const GustyWind* wind_;
  PlantMechanics mechanics_;
  Eigen::Vector3d base_;
  double height_;
  double static_deflection_per_speed2_ = 0.0;  // m / (m/s)^2
  struct Flutter {
    Eigen::Vector3d direction, wave;
    double frequency, phase;
  };
  std::vector<Flutter> flutter_;
};

// Cloud shadows passing over the sun: alternating clear and shaded spells with exponential
// durations (the shaded share of time is the cover), the sun's direct light ramping over the
// edge time between them. The spells are drawn in order from the seed as far as asked for.
class CloudShadows {
 public:
  CloudShadows(const garden::Clouds& clouds, std::uint64_t seed);
  // Fraction of the clear-sky direct sunlight that reaches the garden at time t (0..1).
  double DirectTransmittance(double t) const;

 private:
  void ExtendTo(double t) const;
  garden::Clouds clouds_;
  std::uint64_t seed_;
  mutable std::vector<double> switches_;  // times the sky changes, ascending
  bool starts_shaded_ = false;
};

}  // namespace trimbot::sim
