// The bush's position from stereo: the shape fit on synthetic surface points (exact shapes, a
// neighbour's foliage in the gate, a grown bush), and on rendered frames of the front pair while
// the robot drives at a bush - estimates against the ground truth at every frame.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sim_test_support.h"
#include "trimbot/perception/bush_estimator.h"
#include "trimbot/perception/stereo.h"
#include "trimbot/robot/robot_description.h"

namespace trimbot::perception {
namespace {

// Points on the near side of an ellipsoid (as a camera at the origin sees it), plus `extra`.
PointCloud NearSide(const BushShape& shape, const Eigen::Vector2d& centre, double scale) {
  PointCloud cloud;
  const double a = 0.5 * scale * shape.size.x(), b = 0.5 * scale * shape.size.y(), c = 0.5 * scale * shape.size.z();
  for (double theta = 0.05; theta < M_PI; theta += 0.05) {
    for (double phi = 0.0; phi < 2.0 * M_PI; phi += 0.05) {
      const Eigen::Vector3d local(a * std::sin(theta) * std::cos(phi), b * std::sin(theta) * std::sin(phi),
                                  c * std::cos(theta));
      const double cy = std::cos(shape.yaw), sy = std::sin(shape.yaw);
      const Eigen::Vector3d p(centre.x() + cy * local.x() - sy * local.y(),
                              centre.y() + sy * local.x() + cy * local.y(), shape.base_height + c + local.z());
      if (p.head<2>().norm() > centre.norm()) continue;  // the far side is hidden (roughly)
      cloud.Add(p, Eigen::Matrix3d::Identity() * 1e-6);
    }
  }
  return cloud;
}

TEST(BushFit, FindsAnEllipsoidFromItsNearSideDespiteANeighbourAndGrowth) {
  BushShape shape;
  shape.size = {0.8, 0.55, 0.6};
  shape.yaw = 0.5;
  const Eigen::Vector2d truth(1.3, 0.2);
  PointCloud cloud = NearSide(shape, truth, 1.15);  // grown 15 % since the survey
  BushShape neighbour = shape;
  const PointCloud other = NearSide(neighbour, {1.4, 1.15}, 1.0);  // 0.95 m to the side
  for (std::size_t i = 0; i < other.size(); ++i) cloud.Add(other.points[i], other.covariances[i]);
  const auto estimate = FitBush(cloud, GroundPlane{}, shape, truth + Eigen::Vector2d(-0.15, 0.12));
  ASSERT_TRUE(estimate.has_value());
  // The surveyed size pulls a little (it weighs as much as the points).
  EXPECT_LT((estimate->centre - truth).norm(), 0.01);
  EXPECT_NEAR(estimate->scale, 1.15, 0.03);
}

TEST(BushFit, FindsACylinderAndABox) {
  for (const BushShape::Kind kind : {BushShape::Kind::kCylinder, BushShape::Kind::kBox}) {
    BushShape shape;
    shape.kind = kind;
    shape.size = {0.7, 0.6, 0.65};
    shape.yaw = 0.3;
    const Eigen::Vector2d truth(1.1, -0.3);
    PointCloud cloud;
    const double cy = std::cos(shape.yaw), sy = std::sin(shape.yaw);
    for (double t = 0.0; t < 1.0; t += 0.005) {
      for (double z = 0.05; z < 0.65; z += 0.05) {
        Eigen::Vector2d local;
        if (kind == BushShape::Kind::kCylinder) {
          local = {0.35 * std::cos(2 * M_PI * t), 0.3 * std::sin(2 * M_PI * t)};
        } else {  // walk the box's outline
          const double s = 4.0 * t;
          local = s < 1   ? Eigen::Vector2d(-0.35 + 0.7 * s, -0.3)
                  : s < 2 ? Eigen::Vector2d(0.35, -0.3 + 0.6 * (s - 1))
                  : s < 3 ? Eigen::Vector2d(0.35 - 0.7 * (s - 2), 0.3)
                          : Eigen::Vector2d(-0.35, 0.3 - 0.6 * (s - 3));
        }
        const Eigen::Vector2d p =
            truth + Eigen::Vector2d(cy * local.x() - sy * local.y(), sy * local.x() + cy * local.y());
        if (p.norm() > truth.norm()) continue;
        cloud.Add({p.x(), p.y(), z}, Eigen::Matrix3d::Identity() * 1e-6);
      }
    }
    const auto estimate = FitBush(cloud, GroundPlane{}, shape, truth + Eigen::Vector2d(0.1, 0.1));
    ASSERT_TRUE(estimate.has_value()) << static_cast<int>(kind);
    EXPECT_LT((estimate->centre - truth).norm(), 0.005) << static_cast<int>(kind);
  }
}

TEST(BushFit, SaysWhyWhenNothingIsThere) {
  std::string why;
  EXPECT_FALSE(FitBush(PointCloud{}, GroundPlane{}, BushShape{}, {1.0, 0.0}, {}, &why).has_value());
  EXPECT_NE(why.find("points near the expected bush"), std::string::npos) << why;
}

// The standoff keeps its gap from the outline on the side it stands: an elongated ellipsoid seen
// from its long side is half its short extent deep (until 2026-12-07 the base stood half the
// difference of the extents too far there, out of the arm's reach on Wageningen's bush 34).
TEST(BushShape, AStandoffIsMeasuredFromTheOutlineOnItsSide) {
  BushShape bush;
  bush.size = {0.9, 0.5, 0.4};
  bush.yaw = 0.3;
  EXPECT_NEAR(bush.StandoffRadius(0.3), 0.45, 1e-12);               // the long axis' end
  EXPECT_NEAR(bush.StandoffRadius(0.3 + M_PI / 2.0), 0.25, 1e-12);  // the long side
  EXPECT_NEAR(bush.StandoffRadius(0.3 - M_PI / 2.0), 0.25, 1e-12);
  // In between: the outline point along that bearing lies on the ellipse.
  for (double bearing = -3.0; bearing < 3.2; bearing += 0.37) {
    const double r = bush.StandoffRadius(bearing);
    const double u = r * std::cos(bearing - bush.yaw), v = r * std::sin(bearing - bush.yaw);
    EXPECT_NEAR(u * u / (0.45 * 0.45) + v * v / (0.25 * 0.25), 1.0, 1e-9) << bearing;
  }
  bush.kind = BushShape::Kind::kBox;  // stood at its corners: the larger half extent, as before
  EXPECT_NEAR(bush.StandoffRadius(0.3 + M_PI / 4.0), 0.45, 1e-12);
}

// Rendered: the robot drives at a bush from 3.3 m to 0.9 m (ring centre to bush centre); the front
// pair's cloud is fitted every 0.4 s. The rose has grown since the survey (growth 0.7). The expected centre handed to
// the fit is 12 cm off (a map or localization error), the bush's yaw as the survey gives it.
struct Approach {
  const char* name;
  BushShape shape;
  Eigen::Vector2d position;  // map
  double growth;             // since the survey (Conditions::growth)
};

TEST(RenderedBush, EstimatesWithinBoundsAlongTheApproach) {
  const std::vector<Approach> bushes = {
      {"topiary", {BushShape::Kind::kEllipsoid, {0.8, 0.6, 0.55}, 0.0, 0.5}, {4.0, 0.0}, 0.0},
      {"rose", {BushShape::Kind::kCylinder, {0.7, 0.7, 0.65}, 0.0, 0.0}, {4.0, -4.0}, 0.7},
  };
  std::string objects = "objects:\n";
  for (std::size_t i = 0; i < bushes.size(); ++i) {
    const Approach& b = bushes[i];
    objects += "  - {id: " + std::to_string(i + 1) + ", class: " + (i == 0 ? "topiary" : "rose") +
               ", shape: " + (i == 0 ? "ellipsoid" : "cylinder") + ", size: [" + std::to_string(b.shape.size.x()) +
               ", " + std::to_string(b.shape.size.y()) + ", " + std::to_string(b.shape.size.z()) + "], position: [" +
               std::to_string(b.position.x()) + ", " + std::to_string(b.position.y()) +
               "], yaw_deg: " + std::to_string(b.shape.yaw * 180.0 / M_PI) + "}\n";
  }
  // A neighbour 1.3 m beside the topiary.
  objects += "  - {id: 3, class: topiary, shape: ellipsoid, size: [0.7, 0.7, 0.6], position: [4.2, 1.3]}\n";
  const std::string garden = testing::WriteTempFile(
      "bush_approach.yaml", "name: bush_approach\nseed: 5\nsize: [14, 14]\nground: grass\n" + objects);
  for (const Approach& bush : bushes) {
    sim::SimulatorConfig config = testing::TestConfig(garden, std::string("bush_") + bush.name, true);
    config.cameras_on_schedule = false;
    config.conditions.growth = bush.growth;
    const robot::RobotDescription description = robot::RobotDescription::Load(config.robot.urdf);
    const Eigen::Vector3d ring = description.FramePose(robot::RobotFrames::kCameraRing).translation();
    config.start = {bush.position.x() - 3.3 - ring.x(), bush.position.y(), 0.0};
    sim::Simulator simulator(config);
    const RingStereo stereo(simulator.rig(), StereoOptions{});
    const StereoRectifier& front = stereo.rectifiers()[0];
    messages::RingRequest request;
    request.cameras = {std::min(front.pair().left, front.pair().right),
                       std::max(front.pair().left, front.pair().right)};
    simulator.SetBaseCommand({0.25, 0.0});
    sim::SensorOutputs sensors;
    sim::GroundTruth truth;
    double next = 0.0;
    for (;;) {
      simulator.Step(&sensors, &truth);
      if (simulator.time() < next) continue;
      next += 0.4;
      const Eigen::Isometry3d T_base_map = truth.T_map_base.inverse();
      const Eigen::Vector3d centre = T_base_map * Eigen::Vector3d(bush.position.x(), bush.position.y(), 0.0);
      const Eigen::Vector2d from_ring = centre.head<2>() - ring.head<2>();
      const double distance = from_ring.norm();
      if (distance < 0.9) break;
      const auto result = stereo.ComputePair(simulator.CaptureRing(request, false).frame, 0);
      const auto ground = FitGroundPlane(result.cloud);
      ASSERT_TRUE(ground.has_value());
      BushShape shape = bush.shape;
      shape.yaw -= std::atan2(truth.T_map_base.linear()(1, 0), truth.T_map_base.linear()(0, 0));
      std::string why;
      const auto estimate =
          FitBush(result.cloud, *ground, shape, centre.head<2>() + Eigen::Vector2d(0.1, 0.07), {}, &why);
      ASSERT_TRUE(estimate.has_value()) << bush.name << " at " << distance << " m: " << why;
      const Eigen::Vector2d estimated = estimate->centre - ring.head<2>();
      const double distance_error = estimated.norm() - distance;
      const double bearing_error =
          std::remainder(std::atan2(estimated.y(), estimated.x()) - std::atan2(from_ring.y(), from_ring.x()), 2 * M_PI);
      // Bounds: at the servo's standoff (~1 m) the real robot's final accuracy (1.26 cm); out to
      // 2.2 m the per-frame bound (5 cm, 3 deg). Beyond, SGBM's sub-pixel disparity locks
      // to whole pixels (~5 px there): errors of +-10 cm alternate with distance (a tracker
      // averages them out). A grown bush's outgrowth is irregular, not the surveyed shape scaled:
      // its centre is known less well (measured: up to 1.1 cm at 1.3 m, 5.4 cm at 2.1 m): 1 cm more
      // at every range (beyond 2.2 m too since its shoots grow along the target's normals, out of
      // a cylinder's rim as well: 15.4 cm at 3.15 m).
      const bool grown = bush.growth > 0.0;
      const double bound = distance <= 1.3   ? (grown ? 0.02 : 0.0126)
                           : distance <= 2.2 ? (grown ? 0.06 : 0.05)
                                             : (grown ? 0.16 : 0.15);
      EXPECT_LT(std::abs(distance_error), bound) << bush.name << " at " << distance << " m";
      EXPECT_LT(std::abs(bearing_error), (distance <= 1.3 ? 1.0 : 3.0) * M_PI / 180.0)
          << bush.name << " at " << distance;
    }
  }
}

}  // namespace
}  // namespace trimbot::perception
