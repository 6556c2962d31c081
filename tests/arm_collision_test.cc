// The robot's collision model (FCL) from the URDF: the allowed-collision matrix from adjacency,
// self-collision over joint space, distances against an independent computation, and the
// environment's shapes and perceived points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <map>

#include "test_support.h"
#include "trimbot/robot/collision_model.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/robot/robot_parameters.h"

namespace trimbot::robot {
namespace {

RobotDescription Robot() { return RobotDescription::Load(testing::SourcePath("robot/urdf/trimbot.urdf")); }

// Deterministic joint positions within the URDF's limits (continuous joints over a full turn).
class Configurations {
 public:
  explicit Configurations(const RobotDescription& robot) {
    for (const auto& name : robot.ArmJointNames()) joints_.push_back(robot.urdf().getJoint(name));
  }
  Eigen::VectorXd Next() {
    Eigen::VectorXd q(6);
    for (int i = 0; i < 6; ++i) {
      const auto& joint = *joints_[static_cast<std::size_t>(i)];
      const double u = Uniform();
      q(i) = joint.type == urdf::Joint::REVOLUTE ? joint.limits->lower + (joint.limits->upper - joint.limits->lower) * u
                                                 : -M_PI + 2.0 * M_PI * u;
    }
    return q;
  }

 private:
  double Uniform() {
    state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state_ >> 11) / static_cast<double>(1ULL << 53);
  }
  std::vector<urdf::JointConstSharedPtr> joints_;
  std::uint64_t state_ = 17;
};

TEST(CollisionModel, AllowedPairsAreTheUrdfsAdjacentLinks) {
  const RobotDescription robot = Robot();
  const CollisionModel model(robot, robot.ArmJointNames());
  auto has = [](const auto& pairs, const std::string& a, const std::string& b) {
    for (const auto& [x, y] : pairs) {
      if ((x.rfind(a, 0) == 0 && y.rfind(b, 0) == 0) || (x.rfind(b, 0) == 0 && y.rfind(a, 0) == 0)) return true;
    }
    return false;
  };
  // One moving joint apart: allowed. Rigidly joined to the base through fixed joints: one body.
  EXPECT_TRUE(has(model.allowed_pairs(), "arm_link_1", "arm_link_base"));
  EXPECT_TRUE(has(model.allowed_pairs(), "arm_link_1", "camera_ring_link"));
  EXPECT_TRUE(has(model.allowed_pairs(), "arm_link_5", "arm_link_6"));
  EXPECT_TRUE(has(model.allowed_pairs(), "arm_link_6", "cutter_blade_link"));
  // Two joints apart, or the arm against the base and ring: checked.
  EXPECT_TRUE(has(model.checked_pairs(), "arm_link_2", "camera_ring_link"));
  EXPECT_TRUE(has(model.checked_pairs(), "arm_link_4", "arm_link_6"));
  EXPECT_TRUE(has(model.checked_pairs(), "cutter_blade_link", "base_link"));
  EXPECT_FALSE(has(model.checked_pairs(), "base_link", "camera_ring_link"));  // neither moves
  EXPECT_EQ(model.moving_links().size(), 7u);                                 // six arm links and the cutter
}

TEST(CollisionModel, HomeIsFreeAndNoCheckedPairTouchesEverywhere) {
  const RobotDescription robot = Robot();
  const CollisionModel model(robot, robot.ArmJointNames());
  const RobotParameters parameters = RobotParameters::Load(testing::SourcePath("robot/config/robot_parameters.yaml"));
  const Eigen::VectorXd home = Eigen::Map<const Eigen::VectorXd>(parameters.arm_home_position.data(), 6);
  CollisionCheckOptions with_distance;
  with_distance.distance = true;
  const CollisionReport at_home = model.Check(home, with_distance);
  EXPECT_FALSE(at_home.collision) << at_home.pair.first << " - " << at_home.pair.second;
  EXPECT_GT(at_home.clearance, 0.005);
  // A pair in contact in every configuration would be a URDF geometry error (and block planning).
  Configurations configurations(robot);
  std::map<std::pair<std::string, std::string>, int> contacts;
  CollisionCheckOptions self_only;
  self_only.environment = false;
  int free = 0;
  for (int n = 0; n < 2000; ++n) {
    const CollisionReport report = model.Check(configurations.Next(), self_only);
    if (report.collision)
      ++contacts[report.pair];
    else
      ++free;
  }
  for (const auto& [pair, count] : contacts) EXPECT_LT(count, 1500) << pair.first << " - " << pair.second;
  EXPECT_GT(free, 200);  // a folded arm hits the ring or base often, but far from always
}

// A model built with a body clearance refuses the configurations that bring a moving link closer
// than that to the robot's body (base, ring, arm mount), and those only (the body's shapes are
// grown, not rounded: a box's corner reaches sqrt(3) times as far), and leaves the arm's links
// among themselves as they are; the arm's home keeps it.
TEST(CollisionModel, MovingLinksKeepTheBodyClearanceFromTheRobotsBody) {
  const RobotDescription robot = Robot();
  constexpr double kClearance = 0.01;
  const CollisionModel exact(robot, robot.ArmJointNames());
  const CollisionModel padded(robot, robot.ArmJointNames(), kClearance);
  const RobotParameters parameters = RobotParameters::Load(testing::SourcePath("robot/config/robot_parameters.yaml"));
  const Eigen::VectorXd home = Eigen::Map<const Eigen::VectorXd>(parameters.arm_home_position.data(), 6);
  EXPECT_FALSE(padded.Check(home).collision);
  const auto is_body = [&](const std::string& label) {
    const std::vector<std::string>& moving = exact.moving_links();
    return std::none_of(moving.begin(), moving.end(), [&](const std::string& m) { return label.rfind(m, 0) == 0; });
  };
  CollisionCheckOptions self_distance;
  self_distance.environment = false;
  self_distance.distance = true;
  Configurations configurations(robot);
  int near_body = 0, clear = 0;
  for (int n = 0; n < 3000; ++n) {
    const Eigen::VectorXd q = configurations.Next();
    const CollisionReport report = exact.Check(q, self_distance);
    if (report.collision) continue;
    const bool body_pair = is_body(report.closest.first) || is_body(report.closest.second);
    if (body_pair && report.clearance < kClearance - 1e-4) {
      ++near_body;
      EXPECT_TRUE(padded.Check(q, self_distance).collision) << report.clearance << " m from the body";
    } else if (report.clearance > std::sqrt(3.0) * kClearance + 1e-4) {  // a grown box's corner: sqrt(3) out
      ++clear;
      EXPECT_FALSE(padded.Check(q, self_distance).collision) << report.clearance << " m clear";
    } else if (!body_pair) {
      // Two arm links closer than the clearance, the body farther: no clearance between arm links.
      const CollisionReport p = padded.Check(q, self_distance);
      if (p.collision) {
        EXPECT_TRUE(is_body(p.pair.first) || is_body(p.pair.second)) << p.pair.first << " - " << p.pair.second;
      }
    }
  }
  EXPECT_GT(near_body, 0);
  EXPECT_GT(clear, 100);
}

// The clearance to the ground against the lowest point of each moving cylinder, computed from the
// URDF's link poses without FCL: z_min = centre - half_length |a_z| - radius sqrt(1 - a_z^2).
TEST(CollisionModel, GroundClearanceMatchesTheLowestPointOfTheArm) {
  const RobotDescription robot = Robot();
  CollisionModel model(robot, robot.ArmJointNames());
  model.environment().AddGround("ground", 0.0);
  CollisionCheckOptions options;
  options.self = false;
  options.distance = true;
  Configurations configurations(robot);
  int compared = 0;
  for (int n = 0; n < 300; ++n) {
    const Eigen::VectorXd q = configurations.Next();
    std::map<std::string, double> joints;
    for (int i = 0; i < 6; ++i) joints[robot.ArmJointNames()[static_cast<std::size_t>(i)]] = q(i);
    double lowest = 1e9;
    for (const auto& name : model.moving_links()) {
      const auto link = robot.urdf().getLink(name);
      for (const auto& collision : link->collision_array) {
        const auto& cylinder = static_cast<const urdf::Cylinder&>(*collision->geometry);
        const Eigen::Isometry3d T = robot.FramePose(name, joints) * ToIsometry(collision->origin);
        const double az = std::abs(T.linear()(2, 2));
        lowest = std::min(lowest, T.translation().z() - 0.5 * cylinder.length * az -
                                      cylinder.radius * std::sqrt(std::max(0.0, 1.0 - az * az)));
      }
    }
    const CollisionReport report = model.Check(q, options);
    if (lowest <= 0.0) {
      EXPECT_TRUE(report.collision) << "lowest point " << lowest;
      continue;
    }
    EXPECT_FALSE(report.collision);
    EXPECT_NEAR(report.clearance, lowest, 1e-4);
    ++compared;
  }
  EXPECT_GT(compared, 100);
}

// Perceived points as an octree: a wall of points in front of the arm blocks a reach through it and
// leaves one that stops short free, and the clearance is the gap to the wall's cells.
TEST(CollisionModel, PerceivedPointsBlockWhatReachesThem) {
  const RobotDescription robot = Robot();
  CollisionModel model(robot, robot.ArmJointNames());
  const Eigen::VectorXd q = Configurations(robot).Next();
  CollisionCheckOptions options;
  options.self = false;
  options.distance = true;
  std::map<std::string, double> joints;
  for (int i = 0; i < 6; ++i) joints[robot.ArmJointNames()[static_cast<std::size_t>(i)]] = q(i);
  const Eigen::Vector3d tool = robot.FramePose("arm_end_effector", joints).translation();
  // A plane of points through the tool: in contact. Moved 0.2 m beyond the arm's reach: free.
  auto wall_at = [&](double offset) {
    std::vector<Eigen::Vector3d> points;
    for (double a = -1.0; a <= 1.0; a += 0.01) {
      for (double b = -1.0; b <= 1.0; b += 0.01) points.emplace_back(tool.x() + offset, tool.y() + a, tool.z() + b);
    }
    return points;
  };
  model.environment().AddOccupiedPoints("cloud", wall_at(0.0), 0.02);
  EXPECT_TRUE(model.Check(q, options).collision);
  model.environment().Clear();
  model.environment().AddOccupiedPoints("cloud", wall_at(1.5), 0.02);
  const CollisionReport far = model.Check(q, options);
  EXPECT_FALSE(far.collision);
  EXPECT_GT(far.clearance, 0.1);
  EXPECT_LT(far.clearance, 1.5);
}

}  // namespace
}  // namespace trimbot::robot
