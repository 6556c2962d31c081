// The base's outline against an occupancy grid (stack/navigation/base_outline.h), checked against
// FCL: the same rectangle and the same occupied cells as boxes, distance by FCL's GJK.
#include "trimbot/stack/base_outline.h"

#include <fcl/fcl.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "trimbot/common/random.h"

namespace trimbot::stack {
namespace {

constexpr double kResolution = 0.05;
// The URDF's base outline (chassis 0.70 m long from x = -0.12, wheels' outer faces at +-0.255 m).
const BaseOutline kOutline({-0.12, -0.255}, {0.58, 0.255});

// A 4 x 4 m grid with a box (0.6 x 0.4 m, turned 20 deg) and a cylinder (radius 0.2 m): the cells
// whose centres lie inside them are occupied.
OccupancyGrid MakeGrid() {
  const int n = static_cast<int>(std::lround(4.0 / kResolution));
  cv::Mat occupied(n, n, CV_8U, cv::Scalar(0));
  const Eigen::Vector2d origin(-2.0, -2.0);
  const Pose2 box{-0.6, 0.5, 20.0 * M_PI / 180.0};
  for (int row = 0; row < n; ++row) {
    for (int column = 0; column < n; ++column) {
      const Eigen::Vector2d p = origin + kResolution * Eigen::Vector2d(column + 0.5, n - 1 - row + 0.5);
      const Eigen::Vector2d in_box = IntoFrame(box, p);
      const bool in_the_box = std::abs(in_box.x()) <= 0.3 && std::abs(in_box.y()) <= 0.2;
      const bool in_the_cylinder = (p - Eigen::Vector2d(0.7, -0.6)).norm() <= 0.2;
      if (in_the_box || in_the_cylinder) occupied.at<uchar>(row, column) = 255;
    }
  }
  return OccupancyGrid(occupied, kResolution, origin);
}

// FCL's distance from the outline at `pose` to the grid's occupied cells (all boxes 0.1 m high on
// the same plane); negative when some cell and the outline collide.
double FclClearance(const OccupancyGrid& grid, const Pose2& pose) {
  const Eigen::Vector2d size = kOutline.max() - kOutline.min();
  const Eigen::Vector2d centre = FromFrame(pose, 0.5 * (kOutline.min() + kOutline.max()));
  fcl::Transform3d outline_pose = fcl::Transform3d::Identity();
  outline_pose.translation() << centre.x(), centre.y(), 0.0;
  outline_pose.linear() = Eigen::AngleAxisd(pose.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const fcl::CollisionObjectd outline(std::make_shared<fcl::Boxd>(size.x(), size.y(), 0.1), outline_pose);
  const auto cell_shape = std::make_shared<fcl::Boxd>(kResolution, kResolution, 0.1);
  double clearance = std::numeric_limits<double>::infinity();
  for (int row = 0; row < grid.occupied().rows; ++row) {
    for (int column = 0; column < grid.occupied().cols; ++column) {
      if (grid.occupied().at<uchar>(row, column) == 0) continue;
      const Eigen::Vector2d c = grid.CellCentre({column, row});
      fcl::Transform3d cell_pose = fcl::Transform3d::Identity();
      cell_pose.translation() << c.x(), c.y(), 0.0;
      const fcl::CollisionObjectd cell(cell_shape, cell_pose);
      fcl::CollisionRequestd collision_request;
      fcl::CollisionResultd collision_result;
      if (fcl::collide(&outline, &cell, collision_request, collision_result) > 0) return -1.0;
      fcl::DistanceRequestd request;
      fcl::DistanceResultd result;
      fcl::distance(&outline, &cell, request, result);
      clearance = std::min(clearance, result.min_distance);
    }
  }
  // Beyond the grid all is occupied: four slabs 1 m thick around it.
  const Eigen::Vector2d low = grid.origin(), high = grid.origin() + grid.size(), middle = 0.5 * (low + high);
  const Eigen::Vector2d extent = high - low;
  const std::array<std::pair<Eigen::Vector2d, Eigen::Vector2d>, 4> slabs{{
      {{low.x() - 0.5, middle.y()}, {1.0, extent.y() + 2.0}},
      {{high.x() + 0.5, middle.y()}, {1.0, extent.y() + 2.0}},
      {{middle.x(), low.y() - 0.5}, {extent.x() + 2.0, 1.0}},
      {{middle.x(), high.y() + 0.5}, {extent.x() + 2.0, 1.0}},
  }};
  for (const auto& [slab_centre, slab_size] : slabs) {
    fcl::Transform3d slab_pose = fcl::Transform3d::Identity();
    slab_pose.translation() << slab_centre.x(), slab_centre.y(), 0.0;
    const fcl::CollisionObjectd slab(std::make_shared<fcl::Boxd>(slab_size.x(), slab_size.y(), 0.1), slab_pose);
    fcl::DistanceRequestd request;
    fcl::DistanceResultd result;
    fcl::distance(&outline, &slab, request, result);
    clearance = std::min(clearance, result.min_distance);
  }
  return clearance;
}

TEST(BaseOutline, AgreesWithFclNearABoxAndACylinder) {
  const OccupancyGrid grid = MakeGrid();
  Rng rng = MakeRng(7, "base_outline_test");
  int collisions = 0, clear = 0;
  double worst = 0.0;
  for (int i = 0; i < 300; ++i) {
    // Around the two obstacles, every heading; the grid's edge stays more than a base away.
    const Pose2 pose{-1.0 + 2.0 * UniformUnit(rng), -1.0 + 2.0 * UniformUnit(rng), 2.0 * M_PI * UniformUnit(rng)};
    const double fcl_clearance = FclClearance(grid, pose);
    const double clearance = kOutline.Clearance(grid, pose);
    if (fcl_clearance < 0.0) {
      ++collisions;
      EXPECT_LT(clearance, 0.0) << "pose " << pose.x << ", " << pose.y << ", " << pose.yaw;
    } else {
      ++clear;
      worst = std::max(worst, std::abs(clearance - fcl_clearance));
      EXPECT_NEAR(clearance, fcl_clearance, 1e-6) << "pose " << pose.x << ", " << pose.y << ", " << pose.yaw;
      // With a margin the answer is the same verdict, and exact below it.
      const double bounded = kOutline.Clearance(grid, pose, 0.1);
      if (fcl_clearance < 0.1) {
        EXPECT_NEAR(bounded, fcl_clearance, 1e-6);
      } else {
        EXPECT_GE(bounded, 0.1 - 1e-9);
      }
    }
  }
  std::printf("%d colliding and %d clear poses; largest difference from FCL on the clear ones %.2e m\n", collisions,
              clear, worst);
  // The sample must contain both kinds.
  EXPECT_GT(collisions, 20);
  EXPECT_GT(clear, 20);
}

TEST(BaseOutline, CellsBeyondTheGridAreObstacles) {
  const OccupancyGrid grid = MakeGrid();
  // base_link 0.3 m from the grid's left edge, facing it: the front (0.58 m) is beyond the edge.
  EXPECT_LT(kOutline.Clearance(grid, {-1.7, -1.5, M_PI}), 0.0);
  // Facing away, the back (0.12 m) keeps 0.18 m from the edge.
  EXPECT_NEAR(kOutline.Clearance(grid, {-1.7, -1.5, 0.0}), 0.18, 1e-9);
}

TEST(BaseOutline, TurningOnTheSpotNeverOverstatesTheClearance) {
  const OccupancyGrid grid = MakeGrid();
  // Beside the cylinder: facing away it is clear; turning (clockwise, the shorter way) to face it, not.
  const Pose2 pose{0.7, -0.05, M_PI / 2.0};
  ASSERT_GT(kOutline.Clearance(grid, pose), 0.0);
  const double turn = kOutline.TurnClearance(grid, pose, -M_PI / 2.0 + 0.01, 0.02);
  double finest = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= 2000; ++k) {
    finest = std::min(finest, kOutline.Clearance(grid, {pose.x, pose.y, pose.yaw - (M_PI - 0.01) * k / 2000.0}));
  }
  EXPECT_LT(finest, 0.0);
  EXPECT_LE(turn, finest + 1e-9);
}

}  // namespace
}  // namespace trimbot::stack
