#pragma once
// Seeded random streams. Every noise source draws from its own stream, derived from the run's seed
// and the stream's name, so adding a sensor does not change the noise of the others and the same
// seed always gives the same run.
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

inline std::uint64_t StreamSeed(std::uint64_t seed, std::string_view stream) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a of the stream name
  for (char c : stream) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  return SplitMix64(seed ^ SplitMix64(h));
}

using Rng = std::mt19937_64;

inline Rng MakeRng(std::uint64_t seed, std::string_view stream) { return Rng(StreamSeed(seed, stream)); }

}  // namespace trimbot
