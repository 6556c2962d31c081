#pragma once
// Seeded random streams. Every noise source draws from its own stream, derived from the run's seed
// and the stream's name, so adding a sensor does not change the noise of the others and the same
// seed always gives the same run.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string_view>

namespace trimbot {

inline std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// 64-bit FNV-1a of a text: stream names here, cache keys elsewhere (scenarios/harness/runners/map_cache.cc).
inline std::uint64_t Fnv1a(std::string_view text) {
  std::uint64_t h = 1469598103934665603ULL;
  for (char c : text) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  return h;
}

inline std::uint64_t StreamSeed(std::uint64_t seed, std::string_view stream) {
  return SplitMix64(seed ^ SplitMix64(Fnv1a(stream)));
}

using Rng = std::mt19937_64;

inline Rng MakeRng(std::uint64_t seed, std::string_view stream) { return Rng(StreamSeed(seed, stream)); }

// Portable draws: the std distributions differ between standard libraries, these do not.
// Uniform in [0, 1) from the generator's top 53 bits.
inline double UniformUnit(Rng& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }
// Standard normal by Box-Muller from two uniform draws.
inline double StandardNormal(Rng& rng) {
  const double u1 = std::max(UniformUnit(rng), 1e-300), u2 = UniformUnit(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// Independent standard normal draws, one per coefficient, in index order. (Function arguments are
// evaluated in an unspecified order, so Vector3d(StandardNormal(rng), StandardNormal(rng), ...)
// gives other coefficients with another compiler.)
template <class Vector>
Vector StandardNormalVector(Rng& rng) {
  Vector v;
  for (int i = 0; i < static_cast<int>(v.size()); ++i) v[i] = StandardNormal(rng);
  return v;
}

}  // namespace trimbot
