// The seeded noise replays bit for bit with any standard library and compiler: the generator is
// std::mt19937_64 (its output is fixed by the C++ standard), the stream seeds and the uniform and
// normal draws are the project's own (common/random.h). The expected values below were computed
// by an independent Python implementation of MT19937-64, SplitMix64 and Box-Muller, not by this
// code; a change of any of them changes every recorded trial, so it must be deliberate.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include "trimbot/common/random.h"

namespace trimbot {
namespace {

TEST(PortableRandom, GeneratorIsTheStandardsMersenneTwister) {
  std::mt19937_64 rng;  // default seed 5489
  rng.discard(9999);
  EXPECT_EQ(rng(), 9981545732273789042ULL);  // the value the standard requires of the 10000th draw
}

TEST(PortableRandom, StreamSeedsAndDrawsArePinned) {
  EXPECT_EQ(SplitMix64(0), 0xe220a8397b1dcdafULL);  // SplitMix64's published first output
  const std::uint64_t seed = StreamSeed(42, "imu");
  EXPECT_EQ(seed, 6074797916256058990ULL);
  Rng uniform_rng(seed);
  EXPECT_EQ(UniformUnit(uniform_rng), 0.7602589524958696);
  EXPECT_EQ(UniformUnit(uniform_rng), 0.10518535501827697);
  Rng normal_rng = MakeRng(42, "imu");
  // log and cos come from the platform's libm: equal to within an ulp or two, not bit for bit.
  EXPECT_NEAR(StandardNormal(normal_rng), 0.5845019773993922, 1e-14);
  EXPECT_NEAR(StandardNormal(normal_rng), -1.392018262140139, 1e-14);
  EXPECT_NEAR(StandardNormal(normal_rng), 0.1826647932383071, 1e-14);
}

TEST(PortableRandom, VectorDrawsComeInIndexOrder) {
  Rng a = MakeRng(7, "vector"), b = MakeRng(7, "vector");
  const Eigen::Vector3d v = StandardNormalVector<Eigen::Vector3d>(a);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(v[i], StandardNormal(b));
}

}  // namespace
}  // namespace trimbot
