// The target shape of an overgrown topiary from its leaf points (issue 31, deliverable 2): spheres,
// cylinders and boxes grown up to 5 cm past their target are fitted within 1 cm from points all
// round them; from one side within 5 cm.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "trimbot/common/random.h"
#include "trimbot/garden/conditions.h"
#include "trimbot/garden/foliage.h"
#include "trimbot/perception/topiary_fit.h"

namespace trimbot::perception {
namespace {

struct Case {
  const char* name;
  garden::Shape shape;
  Eigen::Vector3d size;
  AxesTied tied;
};

// The growth (conditions.h) whose shoots reach `overgrowth` past the target: outgrowth is
// growth x kMaxGrowth x (0.4 + 1.2 shoots), shoots up to 1 (garden::FoliageGrowth).
double GrowthFor(double overgrowth) { return overgrowth / (garden::kMaxGrowth * 1.6); }

// The leaf surface as stereo would give it: the side facing `view` (a unit direction from the bush
// towards the camera; zero: all round) with 5 mm noise.
std::vector<Eigen::Vector3d> LeafPoints(const garden::Foliage& foliage, const Eigen::Vector3d& view,
                                        std::uint64_t seed) {
  Rng rng = MakeRng(seed, "leaf_points");
  std::vector<Eigen::Vector3d> points;
  const std::vector<Eigen::Vector3d> surface = foliage.SurfacePoints();
  for (int i = 0; i < foliage.columns(); i += 3) {
    if (!view.isZero() && (foliage.pose().linear() * foliage.direction(i)).dot(view) < 0.2) continue;
    points.push_back(surface[static_cast<std::size_t>(i)] + 0.005 * StandardNormalVector<Eigen::Vector3d>(rng));
  }
  return points;
}

TEST(TopiaryFit, RecoversSpheresCylindersAndBoxesGrownFiveCentimetresPastTheirTarget) {
  const Case cases[] = {{"sphere", garden::Shape::kEllipsoid, {0.7, 0.7, 0.7}, AxesTied::kAll},
                        {"cylinder", garden::Shape::kCylinder, {0.6, 0.6, 0.9}, AxesTied::kHorizontal},
                        {"box", garden::Shape::kBox, {0.8, 0.6, 0.6}, AxesTied::kNone}};
  for (const Case& c : cases) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      garden::GardenObject bush;
      bush.id = static_cast<int>(seed);
      bush.object_class = garden::ObjectClass::kTopiary;
      bush.shape = c.shape;
      bush.size = c.size;
      bush.position = {2.0, 1.0};
      bush.yaw = 0.3;
      const garden::Foliage foliage = garden::Foliage::Grown(bush, 100 + seed, GrowthFor(0.05));
      const garden::Superellipsoid target = garden::TargetShape(bush);
      const Eigen::Vector3d centre = foliage.pose().translation();
      // Seen from the robot's side (south-west, from above the bush's middle) and from all round.
      for (bool one_side : {true, false}) {
        const std::vector<Eigen::Vector3d> all = LeafPoints(
            foliage, one_side ? Eigen::Vector3d(-1.0, -0.6, 0.3).normalized() : Eigen::Vector3d::Zero(), seed);
        TopiaryShape initial;
        initial.horizontal_exponent = target.horizontal_exponent;
        initial.vertical_exponent = target.vertical_exponent;
        initial.centre = centre + Eigen::Vector3d(0.05, -0.04, 0.03);
        initial.yaw = bush.yaw + 0.1;
        initial.half = 1.1 * target.half;
        std::string failure;
        const auto fit = FitTopiary(all, initial, c.tied, {}, &failure);
        ASSERT_TRUE(fit) << failure;
        const double centre_error = (fit->shape.centre - centre).norm();
        const double size_error = (fit->shape.half - target.half).cwiseAbs().maxCoeff();
        std::printf("%-8s seed %lu %s: %zu points, centre %.1f mm off, semi-axes %.1f mm off at most, %.0f %% inside\n",
                    c.name, static_cast<unsigned long>(seed), one_side ? "one side" : "all round", all.size(),
                    1000.0 * centre_error, 1000.0 * size_error, 100.0 * fit->inside_share);
        // From all round (several standoff poses) within 1 cm. From one side the depth is left to
        // the size - a smaller bush further away looks alike - and the box's errors reach 4 cm.
        const double bound = one_side ? 0.05 : 0.01;
        EXPECT_LT(centre_error, bound) << c.name << " seed " << seed << (one_side ? " one side" : "");
        EXPECT_LT(size_error, bound) << c.name << " seed " << seed << (one_side ? " one side" : "");
      }
    }
  }
}

// The test lawn's box at the trim scenarios' growth (0.33: shoots to 8 cm), seen all round above
// the grass (the trim's min_height, robot/config/stack.yaml) with 1 cm of stereo noise. Its foot is
// hidden, so its height and vertical semi-axis trade off: fitted freely, the semi-axis came out
// 1-12 cm long (the bottom under the ground). Standing on the plan's base, the fit is within the
// cut criterion's 2 cm.
TEST(TopiaryFit, ABoxWhoseFootIsHiddenInTheGrassStandsOnThePlansBase) {
  constexpr double kGrassHeight = 0.05, kNoise = 0.01, kTolerance = 0.02;  // m
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    garden::GardenObject bush;
    bush.id = static_cast<int>(seed);
    bush.object_class = garden::ObjectClass::kTopiary;
    bush.shape = garden::Shape::kBox;
    bush.size = {0.6, 0.6, 0.5};
    bush.position = {6.0, 1.0};
    bush.yaw = 0.52;
    const garden::Foliage foliage = garden::Foliage::Grown(bush, 100 + seed, 0.33);
    const garden::Superellipsoid target = garden::TargetShape(bush);
    Rng rng = MakeRng(seed, "leaf_points");
    std::vector<Eigen::Vector3d> points;
    for (const Eigen::Vector3d& leaf : foliage.SurfacePoints()) {
      const Eigen::Vector3d p = leaf + kNoise * StandardNormalVector<Eigen::Vector3d>(rng);
      if (p.z() >= kGrassHeight) points.push_back(p);
    }
    TopiaryShape initial;
    initial.horizontal_exponent = target.horizontal_exponent;
    initial.vertical_exponent = target.vertical_exponent;
    initial.centre = foliage.pose().translation() + Eigen::Vector3d(0.05, -0.04, 0.03);
    initial.yaw = bush.yaw + 0.1;
    initial.half = 1.1 * target.half;
    TopiaryFitOptions options;
    options.base_height = bush.base_height;
    std::string failure;
    const auto fit = FitTopiary(points, initial, AxesTied::kHorizontal, options, &failure);
    ASSERT_TRUE(fit) << failure;
    const double centre_error = (fit->shape.centre - foliage.pose().translation()).norm();
    const double size_error = (fit->shape.half - target.half).cwiseAbs().maxCoeff();
    std::printf("box seed %lu above the grass: centre %.1f mm off, semi-axes %.1f mm off at most\n",
                static_cast<unsigned long>(seed), 1000.0 * centre_error, 1000.0 * size_error);
    EXPECT_LT(centre_error, kTolerance) << "seed " << seed;
    EXPECT_LT(size_error, kTolerance) << "seed " << seed;
  }
}

TEST(TopiaryFit, TooFewPointsAreAFailureWithTheReason) {
  std::string failure;
  EXPECT_FALSE(FitTopiary(std::vector<Eigen::Vector3d>(10, Eigen::Vector3d::Zero()), {}, AxesTied::kAll, {}, &failure));
  EXPECT_NE(failure.find("10 points"), std::string::npos) << failure;
}

}  // namespace
}  // namespace trimbot::perception
