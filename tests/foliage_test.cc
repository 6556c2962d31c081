// Foliage that can be cut (issue 31, deliverable 1): a blade disc's sweep removes exactly the
// foliage beyond where it crossed each column, and the cut is measured against the target.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "trimbot/garden/foliage.h"

namespace trimbot::garden {
namespace {

GardenObject Topiary(Shape shape, const Eigen::Vector3d& size) {
  GardenObject bush;
  bush.id = 7;
  bush.object_class = ObjectClass::kTopiary;
  bush.shape = shape;
  bush.size = size;
  bush.position = {1.0, -2.0};
  bush.yaw = 0.4;
  return bush;
}

// Brute force: column i's height at the first point from its base, in 1 mm steps, that some
// position of the disc on its way (1000 steps) holds within half a millimetre of its plane. A point
// farther than the disc's rim from every centre on the way is passed over without the 1000 steps
// (the test's cost under the sanitizers, not its answer).
double BruteForceCut(const Foliage& foliage, int i, const BladeDisc& from, const BladeDisc& to) {
  const Eigen::Vector3d axis = from.axis.normalized();
  const double depth = (foliage.root(i) - foliage.base(i)).norm();
  const Eigen::Vector3d way = to.centre - from.centre;
  for (double s = 0.0; s < depth + foliage.height(i); s += 0.001) {
    const Eigen::Vector3d q = foliage.pose() * (foliage.base(i) + s * foliage.normal(i));
    const double along = std::clamp((q - from.centre).dot(way) / way.squaredNorm(), 0.0, 1.0);
    if ((q - from.centre - along * way).norm() > from.radius + 0.001) continue;
    for (int k = 0; k <= 1000; ++k) {
      const Eigen::Vector3d c = from.centre + way * (k / 1000.0);
      const Eigen::Vector3d v = q - c;
      if (std::abs(v.dot(axis)) <= 0.0005 && (v - v.dot(axis) * axis).norm() <= from.radius) return s - depth;
    }
  }
  return foliage.height(i);
}

TEST(Foliage, ASweepInItsPlaneSeversEveryColumnItCrossesWhereItCrossesIt) {
  const GardenObject bush = Topiary(Shape::kEllipsoid, {0.7, 0.7, 0.6});
  Foliage foliage = Foliage::Grown(bush, 5, 0.5, 30, 60);
  const Foliage before = foliage;
  // A horizontal disc 0.15 m above the centre, 0.1 m in radius, moving 0.8 m along the map's x.
  BladeDisc from, to;
  from.centre = foliage.pose() * Eigen::Vector3d(0.0, 0.0, 0.15) - Eigen::Vector3d(0.4, 0.0, 0.0);
  to.centre = from.centre + Eigen::Vector3d(0.8, 0.0, 0.0);
  from.radius = to.radius = 0.1;
  foliage.Cut(from, to);
  int cut = 0;
  for (int i = 0; i < foliage.columns(); ++i) {
    const Eigen::Vector3d base = foliage.base(i), n = foliage.normal(i);
    const double depth = (foliage.root(i) - base).norm();
    double expected = before.height(i);
    if (n.z() > 0.0) {
      // Where the column's line crosses the disc's plane, and whether the disc's path passed there.
      const double s = (0.15 - base.z()) / n.z();
      const Eigen::Vector3d q = foliage.pose() * (base + s * n);
      const double along = std::clamp((q - from.centre).x() / 0.8, 0.0, 1.0);
      if (s >= 0.0 && s - depth < before.height(i) &&
          (q - (from.centre + along * (to.centre - from.centre))).norm() <= 0.1) {
        expected = s - depth;
      }
    }
    EXPECT_NEAR(foliage.height(i), expected, 1e-9) << "column " << i;
    cut += foliage.height(i) < before.height(i) ? 1 : 0;
  }
  EXPECT_GT(cut, 20) << "the sweep crossed the bush";
  EXPECT_LT(cut, foliage.columns() / 3);
}

TEST(Foliage, AnObliqueSweepAgreesWithABruteForceSweep) {
  const GardenObject bush = Topiary(Shape::kBox, {0.6, 0.5, 0.5});
  Foliage foliage = Foliage::Grown(bush, 9, 1.0, 16, 32);
  const Foliage before = foliage;
  // A tilted disc plunging sideways into the bush's top corner: the move has a component along
  // its axis, so the swept volume is an oblique cylinder.
  BladeDisc from, to;
  from.axis = to.axis = Eigen::Vector3d(0.3, 0.2, 1.0).normalized();
  from.centre = foliage.pose() * Eigen::Vector3d(0.35, 0.0, 0.35);
  to.centre = foliage.pose() * Eigen::Vector3d(0.05, 0.1, 0.15);
  from.radius = to.radius = 0.12;
  foliage.Cut(from, to);
  int cut = 0;
  for (int i = 0; i < foliage.columns(); ++i) {
    EXPECT_NEAR(foliage.height(i), BruteForceCut(before, i, from, to), 0.004) << "column " << i;
    cut += foliage.height(i) < before.height(i) - 1e-9 ? 1 : 0;
  }
  EXPECT_GT(cut, 5);
}

// A point is in the foliage when it lies at most its column's height out along the column: just
// inside and just outside each column's tip, on boxes and on a long ellipsoid whose columns fan out
// fast at its ends (their lines 16 cm from their common centre of curvature there).
TEST(Foliage, EveryColumnEndsAtItsTip) {
  for (const GardenObject& bush :
       {Topiary(Shape::kEllipsoid, {0.8, 0.6, 0.5}), Topiary(Shape::kBox, {0.8, 0.6, 0.7})}) {
    const Foliage foliage = Foliage::Grown(bush, 3, 0.6);
    int wrong = 0;
    for (int i = 0; i < foliage.columns(); ++i) {
      if (foliage.OnTheGround(i, 0.004)) continue;  // no leaf below the ground
      const Eigen::Vector3d tip = foliage.pose() * foliage.tip(i), n = foliage.pose().linear() * foliage.normal(i);
      wrong += !foliage.Reaches(tip - 0.002 * n) || foliage.Reaches(tip + 0.002 * n) ? 1 : 0;
    }
    EXPECT_EQ(wrong, 0) << "of " << foliage.columns() << " columns";
  }
}

TEST(Foliage, CuttingOffTheCrownIsMeasuredAsOvercut) {
  const GardenObject bush = Topiary(Shape::kEllipsoid, {0.8, 0.6, 0.5});
  Foliage foliage = Foliage::Grown(bush, 3, 0.6);
  const CutQuality grown = foliage.Measure();
  const double a = 0.4, b = 0.3, c = 0.25, h = 0.1;
  const double ellipsoid = 4.0 / 3.0 * M_PI * a * b * c;
  EXPECT_NEAR(grown.target_volume, ellipsoid, 0.002 * ellipsoid);
  EXPECT_GT(grown.overgrowth_volume, 0.0);
  EXPECT_LT(grown.overcut_volume, 0.02 * ellipsoid) << "leaf clumps dip below the target here and there";
  // A blade larger than the bush, level 0.1 m above its centre, passing right across: the target's
  // cap above that plane is over-cut, what grew below it stays.
  BladeDisc from, to;
  from.centre = foliage.pose() * Eigen::Vector3d(-1.0, 0.0, h);
  to.centre = foliage.pose() * Eigen::Vector3d(1.0, 0.0, h);
  from.radius = to.radius = 1.0;
  foliage.Cut(from, to);
  const CutQuality capped = foliage.Measure();
  const double cap = M_PI * a * b * (c - h) * (c - h) * (2.0 * c + h) / (3.0 * c * c);
  EXPECT_NEAR(capped.overcut_volume, cap, 0.03 * cap);
  EXPECT_LT(capped.overgrowth_volume, grown.overgrowth_volume);
  EXPECT_GT(capped.overgrowth_volume, 0.3 * grown.overgrowth_volume);
  for (int i = 0; i < foliage.columns(); ++i) EXPECT_LE(foliage.tip(i).z(), h + 1e-9);
  // The drawn surface follows the cut: moved back along its columns, the grown surface lies below
  // the blade's plane and where it grew below the plane it stays, both but for the columns' 2 deg
  // grid (a point moved back along its column's normal ends level with the column's tip across
  // that normal, not across the blade's plane: a step of up to half a cell, 7 mm at 0.4 m, times
  // the normal's lean off the plane's).
  const FoliageGrowth growth(bush, 3, 0.6);
  for (int k = 0; k < 500; ++k) {
    const double z = 1.0 - (k + 0.5) / 250.0, r = std::sqrt(1.0 - z * z), angle = 2.39996 * k;
    Eigen::Vector3d p = growth.SurfacePoint({r * std::cos(angle), r * std::sin(angle), z});
    p.z() = std::max(p.z(), -c);  // as drawn: never below the bottom
    const Eigen::Vector3d drawn = foliage.CutBack(p);
    EXPECT_LE(drawn.z(), h + 0.01) << "surface point " << k;
    if (p.z() < h) {
      EXPECT_LT((drawn - p).norm(), 0.005) << "surface point " << k;
    }
  }
  std::printf("grown: %.1f %% of the surface within 2 cm, %.1f l overgrowth; capped: %.2f l over-cut (cap %.2f l)\n",
              100.0 * grown.surface_within_tolerance, 1000.0 * grown.overgrowth_volume, 1000.0 * capped.overcut_volume,
              1000.0 * cap);
}

TEST(Foliage, GrowthLowersTheShareOfTheSurfaceNearTheTarget) {
  for (Shape shape : {Shape::kEllipsoid, Shape::kCylinder, Shape::kBox}) {
    const GardenObject bush = Topiary(shape, {0.7, 0.7, 0.7});
    const CutQuality trimmed = Foliage::Grown(bush, 1, 0.0).Measure();
    const CutQuality grown = Foliage::Grown(bush, 1, 0.5).Measure();
    EXPECT_GT(trimmed.surface_within_tolerance, 0.9) << "leaf clumps alone stay within 2 cm";
    EXPECT_LT(grown.surface_within_tolerance, 0.5 * trimmed.surface_within_tolerance);
    EXPECT_GT(grown.max_overgrowth, 0.4 * 0.5 * 0.15);
  }
}

// The share leaves out the surface the bush stands on (no leaf grows out of a box's underside: it
// would count as within 2 cm however the bush was cut), and is also given over the upper half,
// which the arm reaches: a ball's upper half cut to its target by blades plunged in all over it
// is within 2 cm there, the whole bush well short of that.
TEST(Foliage, TheShareLeavesOutTheGroundAndIsGivenOverTheUpperHalf) {
  const Foliage box = Foliage::Grown(Topiary(Shape::kBox, {0.8, 0.8, 0.7}), 2, 0.5);
  int on_the_ground = 0;
  for (int i = 0; i < box.columns(); ++i) {
    const double z = box.direction(i).z();
    if (z < -0.95) {
      EXPECT_TRUE(box.OnTheGround(i, 0.02)) << "column " << i << " ends at the underside";
    }
    if (box.OnTheGround(i, 0.02)) {
      EXPECT_LT(z, -0.4) << "column " << i;
      ++on_the_ground;
    }
  }
  EXPECT_GT(on_the_ground, 100);
  Foliage ball = Foliage::Grown(Topiary(Shape::kEllipsoid, {0.7, 0.7, 0.7}), 2, 0.5);
  for (int i = 0; i < ball.columns(); ++i) {
    if (ball.OnTheGround(i, 0.02)) {
      EXPECT_LT(ball.direction(i).z(), -std::cos(0.35)) << "a ball rests on a point";
    }
  }
  const CutQuality grown = ball.Measure();
  // Discs plunged along the target's inward normal from 15 cm out to 5 mm inside it, every ~4 cm
  // over the upper half (a Fibonacci hemisphere).
  const Superellipsoid& target = ball.target();
  for (int k = 0; k < 400; ++k) {
    const double z = 1.0 - (k + 0.5) / 400.0, r = std::sqrt(1.0 - z * z), a = 2.39996 * k;
    const Eigen::Vector3d d(r * std::cos(a), r * std::sin(a), z);
    const Eigen::Vector3d surface = target.Radius(d) * d, normal = target.Normal(surface);
    BladeDisc from, to;
    from.centre = ball.pose() * (surface + 0.15 * normal);
    to.centre = ball.pose() * (surface - 0.005 * normal);
    from.axis = to.axis = ball.pose().linear() * normal;
    from.radius = to.radius = 0.05;
    ball.Cut(from, to);
  }
  const CutQuality cut = ball.Measure();
  std::printf(
      "grown ball: %.1f %% within 2 cm (upper half %.1f %%); its upper half cut: %.1f %% (upper half %.1f %%)\n",
      100.0 * grown.surface_within_tolerance, 100.0 * grown.upper_surface_within_tolerance,
      100.0 * cut.surface_within_tolerance, 100.0 * cut.upper_surface_within_tolerance);
  EXPECT_LT(grown.upper_surface_within_tolerance, 0.5);
  EXPECT_GT(cut.upper_surface_within_tolerance, 0.9);
  EXPECT_LT(cut.surface_within_tolerance, cut.upper_surface_within_tolerance - 0.3);
}

// The blade (0.05 m radius) pushed in along -out from 0.2 m outside to `at` (map frame). Its housing
// is the last link's 0.03 m cylinder, 1 cm behind the disc, 0.13 m long.
void PlungeBlade(Foliage* foliage, const Eigen::Vector3d& at, const Eigen::Vector3d& out) {
  BladeDisc from, to;
  from.centre = at + 0.2 * out;
  to.centre = at;
  from.axis = to.axis = out;
  from.radius = to.radius = 0.05;
  foliage->Cut(from, to);
}

TEST(Foliage, AHousingBehindABladeThatCutItsWayInIsClearOfTheLeavesBesideItIsNot) {
  const GardenObject bush = Topiary(Shape::kEllipsoid, {0.7, 0.7, 0.7});
  Foliage foliage = Foliage::Grown(bush, 4, 0.5);
  // The blade pushed in along -x to the target's surface on the +x side.
  const Eigen::Vector3d out = foliage.pose().linear() * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d surface = foliage.pose() * Eigen::Vector3d(0.35, 0.0, 0.0);
  const Eigen::Vector3d a = surface + 0.01 * out, b = a + 0.13 * out;
  EXPECT_TRUE(foliage.ReachesCylinder(a, b, 0.03)) << "the leaves stand there before the cut";
  PlungeBlade(&foliage, surface, out);
  EXPECT_FALSE(foliage.ReachesCylinder(a, b, 0.03));
  // The same housing 0.1 m to the side, beyond the blade's swept disc: in uncut leaves.
  const Eigen::Vector3d side = foliage.pose().linear() * Eigen::Vector3d(0.0, 0.1, 0.0);
  EXPECT_TRUE(foliage.ReachesCylinder(a + side, b + side, 0.03));
  // Only its mantle reaches in when it lies along the surface just outside the leaves' tips.
  int crown = 0;  // the column at the top
  for (int i = 0; i < foliage.columns(); ++i)
    crown = foliage.direction(i).z() > foliage.direction(crown).z() ? i : crown;
  const Eigen::Vector3d tip = foliage.pose() * foliage.tip(crown);
  const Eigen::Vector3d up = foliage.pose().linear() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d along = foliage.pose().linear() * Eigen::Vector3d(0.0, 0.06, 0.0);
  EXPECT_TRUE(foliage.ReachesCylinder(tip + 0.02 * up - along, tip + 0.02 * up + along, 0.03));
  double top = 0.0;  // m above the centre: the highest leaf
  for (int i = 0; i < foliage.columns(); ++i) top = std::max(top, foliage.tip(i).z());
  const Eigen::Vector3d above = foliage.pose() * Eigen::Vector3d(0.0, 0.0, top + 0.04);
  EXPECT_FALSE(foliage.ReachesCylinder(above - along, above + along, 0.03)) << "1 cm above the highest leaf";
}

// Leaves grow out along the target's normal: near a box's corner, a blade plunged along a face's
// normal to the target clears the housing behind it (radial columns from the centre lean 30 deg
// off that normal there: leaves rooted beside the blade's swath would hang over its housing).
TEST(Foliage, AHousingBehindABladePlungedNearABoxCornerIsClearOfTheLeaves) {
  const GardenObject bush = Topiary(Shape::kBox, {0.8, 0.8, 0.7});
  Foliage foliage = Foliage::Grown(bush, 6, 0.5);
  for (const Eigen::Vector3d& on_face :
       {Eigen::Vector3d(0.4, 0.25, 0.2), Eigen::Vector3d(0.4, -0.28, 0.22), Eigen::Vector3d(0.3, 0.3, 0.35)}) {
    Foliage cut = foliage;
    const Eigen::Vector3d surface = cut.target().Radius(on_face.normalized()) * on_face.normalized();
    const Eigen::Vector3d n = cut.target().Normal(surface);
    const Eigen::Vector3d out = cut.pose().linear() * n, at = cut.pose() * surface;
    const Eigen::Vector3d a = at + 0.01 * out, b = a + 0.13 * out;
    EXPECT_TRUE(cut.ReachesCylinder(a, b, 0.03)) << "the leaves stand there before the cut";
    PlungeBlade(&cut, at, out);
    EXPECT_FALSE(cut.ReachesCylinder(a, b, 0.03)) << "housing behind the blade at " << on_face.transpose();
    EXPECT_TRUE(cut.ReachesCylinder(a, b, 0.06)) << "leaves just beyond the blade's 5 cm stand";
  }
}

TEST(Foliage, WritesItsSurfaceAsPly) {
  const Foliage foliage = Foliage::Grown(Topiary(Shape::kCylinder, {0.5, 0.5, 0.8}), 2, 0.3, 10, 20);
  const std::string path = (std::filesystem::temp_directory_path() / "trimbot_foliage_test.ply").string();
  foliage.WritePly(path);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t header = bytes.find("end_header\n");
  ASSERT_NE(header, std::string::npos);
  EXPECT_NE(bytes.find("element vertex 200"), std::string::npos);
  EXPECT_EQ(bytes.size() - (header + 11), 200u * 16u);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace trimbot::garden
