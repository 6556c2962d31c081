#include "trimbot/sim/weather.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <string>

#include "trimbot/common/random.h"

namespace trimbot::sim {

namespace {

constexpr double kAirDensity = 1.2;  // kg/m^3
// A weather station measures over open grass (WMO-No. 8, Part I, Ch. 5: z0 ~0.03 m, 10 m mast);
// the profile is carried up to a blending height where the surface no longer matters, then down
// over the garden's own roughness.
constexpr double kStationHeight = 10.0, kStationRoughness = 0.03, kBlendingHeight = 60.0;
// Gusts: frequencies from 0.005 Hz (minutes) to 5 Hz in log-spaced bins, one sinusoid each.
constexpr int kGustComponents = 24;
constexpr double kLowestGust = 0.005, kHighestGust = 5.0;
constexpr double kSpectrumHeight = 1.0;  // m, the plants' height, where the spectrum is taken
constexpr int kFlutterModes = 3;

// Kaimal et al. (1972) along-wind spectrum, n S(n) / u*^2 = 105 f / (1 + 33 f)^(5/3), f = n z / U;
// returned per unit frequency, up to a constant (normalized below).
double KaimalDensity(double n, double height, double mean_speed) {
  const double f = n * height / mean_speed;
  return 105.0 * f / std::pow(1.0 + 33.0 * f, 5.0 / 3.0) / n;
}

// Mean speed at `height` over roughness z0 of the mean `speed10` a station measures.
double LogProfileSpeed(double speed10, double height, double z0) {
  const double blending =
      speed10 * std::log(kBlendingHeight / kStationRoughness) / std::log(kStationHeight / kStationRoughness);
  height = std::max(height, 2.0 * z0);  // the log law holds above the roughness elements
  return blending * std::log(height / z0) / std::log(kBlendingHeight / z0);
}

// EN 1991-1-4, Eq. 4.7 (turbulence factor and orography factor 1): I = 1 / ln(z / z0).
double TurbulenceIntensity(double height, double z0) { return 1.0 / std::log(std::max(height, 2.0 * z0) / z0); }

}  // namespace

GustyWind::GustyWind(const garden::Wind& wind, std::uint64_t seed) : wind_(wind), seed_(seed) {
  Rng rng = MakeRng(seed, "wind");
  const double heading = 2.0 * M_PI * UniformUnit(rng);
  direction_ = Eigen::Vector2d(std::cos(heading), std::sin(heading));
  const double mean = MeanSpeedAt(kSpectrumHeight);
  if (mean <= 0.0) return;
  std::vector<double> weights;
  const double ratio = std::pow(kHighestGust / kLowestGust, 1.0 / kGustComponents);
  double total = 0.0;
  for (int k = 0; k < kGustComponents; ++k) {
    const double low = kLowestGust * std::pow(ratio, k), high = low * ratio;
    const double frequency = low * std::pow(ratio, UniformUnit(rng));
    const double weight = KaimalDensity(frequency, kSpectrumHeight, mean) * (high - low);
    components_.push_back({frequency, weight, 2.0 * M_PI * UniformUnit(rng)});
    total += weight;
  }
  // Unit variance: each sinusoid carries amplitude^2 / 2.
  for (Component& c : components_) c.amplitude = std::sqrt(2.0 * c.amplitude / total);
}

double GustyWind::MeanSpeedAt(double height) const {
  return LogProfileSpeed(wind_.mean_speed, height, wind_.roughness_length);
}

double GustyWind::Gust(const Eigen::Vector2d& position, double t) const {
  const double mean = MeanSpeedAt(kSpectrumHeight);
  if (mean <= 0.0) return 0.0;
  const double arrival = t - direction_.dot(position) / mean;  // gusts drift with the mean wind
  double sum = 0.0;
  for (const Component& c : components_) sum += c.amplitude * std::cos(2.0 * M_PI * c.frequency * arrival + c.phase);
  return sum;
}

double GustyWind::SpeedAt(const Eigen::Vector2d& position, double height, double t) const {
  const double mean = MeanSpeedAt(height);
  return std::max(0.0, mean * (1.0 + TurbulenceIntensity(height, wind_.roughness_length) * Gust(position, t)));
}

PlantMechanics MechanicsOf(garden::ObjectClass object_class) {
  PlantMechanics shrub;
  // Shrubs and crops sway at 1-3 Hz (Py, de Langre & Moulia 2006, J. Fluid Mech.), damping ratio
  // 0.05-0.2 (James, Haritos & Ades 2006, Am. J. Bot. 93:1522); a leafy crown's drag coefficient
  // after reconfiguration ~0.5 (Vogel 1989, J. Exp. Bot. 40:941; de Langre 2008, Annu. Rev. Fluid
  // Mech. 40:141). The crown's modal mass per frontal area has no measured source here: estimated
  // from ~5 kg of fresh mass of a clipped 1 m shrub over ~0.8 m^2, a quarter of it in the first
  // mode. Leaves flutter at 5-20 Hz (same reviews); their amplitude per m/s of wind (2 mm) is an
  // estimate of the same kind, a fraction of a leaf's size at a breeze.
  shrub.sway_frequency = 2.0;
  shrub.sway_damping = 0.1;
  shrub.crown_mass_per_area = 1.5;
  shrub.drag_coefficient = 0.5;
  shrub.flutter_amplitude_per_speed = 0.002;
  shrub.flutter_frequency = 8.0;
  shrub.flutter_wavelength = 0.12;  // the foliage meshes' leaf clumps
  switch (object_class) {
    case garden::ObjectClass::kTopiary:
    case garden::ObjectClass::kRose:
    case garden::ObjectClass::kHedge:
      return shrub;
    case garden::ObjectClass::kTree: {
      // Trees sway at 0.2-1 Hz (Moore & Maguire 2004, Trees 18:195); a heavier crown (estimate).
      PlantMechanics tree = shrub;
      tree.sway_frequency = 0.5;
      tree.crown_mass_per_area = 5.0;
      tree.flutter_wavelength = 0.4;  // the crowns' clumps
      return tree;
    }
    default:
      return {};
  }
}

PlantMotion::PlantMotion(const GustyWind& wind, garden::ObjectClass object_class, int object_id,
                         const Eigen::Vector3d& base, double height)
    : wind_(&wind), mechanics_(MechanicsOf(object_class)), base_(base), height_(std::max(height, 1e-3)) {
  if (!moves()) return;
  const double omega = 2.0 * M_PI * mechanics_.sway_frequency;
  static_deflection_per_speed2_ =
      kAirDensity * mechanics_.drag_coefficient / (2.0 * mechanics_.crown_mass_per_area * omega * omega);
  Rng rng = MakeRng(wind.seed(), "plant/" + std::to_string(object_id));
  for (int j = 0; j < kFlutterModes; ++j) {
    Flutter f;
    f.direction = StandardNormalVector<Eigen::Vector3d>(rng).normalized();
    f.wave = StandardNormalVector<Eigen::Vector3d>(rng).normalized() * (2.0 * M_PI / mechanics_.flutter_wavelength);
    f.frequency = mechanics_.flutter_frequency * (0.7 + 0.6 * UniformUnit(rng));
    f.phase = 2.0 * M_PI * UniformUnit(rng);
    flutter_.push_back(f);
  }
}

double PlantMotion::Sway(double t) const {
  if (!moves()) return 0.0;
  const double mean = wind_->MeanSpeedAt(base_.z() + height_);
  if (mean <= 0.0) return 0.0;
  const double sigma = mean * TurbulenceIntensity(base_.z() + height_, wind_->wind().roughness_length);
  // Drag ~ u^2 = U^2 + 2 U u' (+ u'^2, left out): the mean bends the crown statically; each gust
  // sinusoid drives the crown's oscillator, H(r) = 1 / (1 - r^2 + 2 i zeta r).
  const Eigen::Vector2d position = base_.head<2>();
  const double arrival = t - wind_->direction().dot(position) / wind_->MeanSpeedAt(kSpectrumHeight);
  double gust = 0.0;
  for (const GustyWind::Component& c : wind_->components()) {
    const double r = c.frequency / mechanics_.sway_frequency;
    const std::complex<double> response = 1.0 / std::complex<double>(1.0 - r * r, 2.0 * mechanics_.sway_damping * r);
    gust +=
        c.amplitude * std::abs(response) * std::cos(2.0 * M_PI * c.frequency * arrival + c.phase - std::arg(response));
  }
  return static_deflection_per_speed2_ * (mean * mean + 2.0 * mean * sigma * gust);
}

Eigen::Vector3d PlantMotion::Displacement(const Eigen::Vector3d& point, double t) const {
  if (!moves()) return Eigen::Vector3d::Zero();
  const double s = std::clamp((point.z() - base_.z()) / height_, 0.0, 1.0);
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();
  displacement.head<2>() = s * s * Sway(t) * wind_->direction();
  const double speed = wind_->SpeedAt(base_.head<2>(), base_.z() + height_, t);
  const double amplitude = mechanics_.flutter_amplitude_per_speed * speed * s / std::sqrt(double{kFlutterModes});
  for (const Flutter& f : flutter_) {
    displacement += amplitude * f.direction * std::cos(f.wave.dot(point) + 2.0 * M_PI * f.frequency * t + f.phase);
  }
  return displacement;
}

double PlantMotion::MaxDisplacement() const {
  if (!moves()) return 0.0;
  const double mean = wind_->MeanSpeedAt(base_.z() + height_);
  const double sigma = mean * TurbulenceIntensity(base_.z() + height_, wind_->wind().roughness_length);
  // A sum of sinusoids never exceeds the sum of their amplitudes.
  double gust = 0.0, speed = 0.0;
  for (const GustyWind::Component& c : wind_->components()) {
    const double r = c.frequency / mechanics_.sway_frequency;
    gust += c.amplitude * std::abs(1.0 / std::complex<double>(1.0 - r * r, 2.0 * mechanics_.sway_damping * r));
    speed += c.amplitude;
  }
  const double sway = static_deflection_per_speed2_ * (mean * mean + 2.0 * mean * sigma * gust);
  return sway + mechanics_.flutter_amplitude_per_speed * (mean + sigma * speed) * std::sqrt(double{kFlutterModes});
}

CloudShadows::CloudShadows(const garden::Clouds& clouds, std::uint64_t seed) : clouds_(clouds), seed_(seed) {
  Rng rng = MakeRng(seed_, "clouds/start");
  starts_shaded_ = UniformUnit(rng) < clouds_.cover;
}

void CloudShadows::ExtendTo(double t) const {
  // Spell k's length comes from its own stream.
  while (switches_.empty() || switches_.back() <= t) {
    const bool shaded = starts_shaded_ == (switches_.size() % 2 == 0);
    const double mean =
        shaded ? clouds_.mean_shadow_duration : clouds_.mean_shadow_duration * (1.0 - clouds_.cover) / clouds_.cover;
    Rng rng = MakeRng(seed_, "clouds/" + std::to_string(switches_.size()));
    const double length = -mean * std::log(1.0 - UniformUnit(rng));
    switches_.push_back((switches_.empty() ? 0.0 : switches_.back()) + length);
  }
}

double CloudShadows::DirectTransmittance(double t) const {
  if (clouds_.cover <= 0.0) return 1.0;
  if (clouds_.cover >= 1.0) return clouds_.direct_transmittance;
  ExtendTo(t + clouds_.edge_duration);
  const auto level = [&](std::size_t spell) {
    const bool shaded = starts_shaded_ == (spell % 2 == 0);
    return shaded ? clouds_.direct_transmittance : 1.0;
  };
  const std::size_t spell = std::upper_bound(switches_.begin(), switches_.end(), t) - switches_.begin();
  double transmittance = level(spell);
  // Ramp across the nearest edge (either side of it).
  const double half = 0.5 * clouds_.edge_duration;
  for (std::size_t k : {spell, spell == 0 ? spell : spell - 1}) {
    if (k >= switches_.size() || half <= 0.0) continue;
    const double from_edge = t - switches_[k];
    if (std::abs(from_edge) < half) {
      const double w = 0.5 + 0.5 * from_edge / half;
      transmittance = (1.0 - w) * level(k) + w * level(k + 1);
    }
  }
  return transmittance;
}

}  // namespace trimbot::sim
