// Arm motion planning (OMPL + the FCL collision model): collision-free, timed paths to cutter poses
// around a bush-sized obstacle, clear failures for poses that cannot be reached, straight cutting
// passes, and a roadmap reused between queries.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "test_support.h"
#include "trimbot/arm/arm_planner.h"
#include "trimbot/robot/robot_parameters.h"

namespace trimbot::arm {
namespace {

struct Fixture {
  robot::RobotDescription robot = robot::RobotDescription::Load(testing::SourcePath("robot/urdf/trimbot.urdf"));
  ArmKinematics kinematics{robot};
  robot::CollisionModel collision{robot, robot.ArmJointNames()};
  Eigen::VectorXd home = Home();
  // A bush in front of the robot, as the planner is told of it, and the ground.
  Fixture() {
    collision.environment().AddGround("ground", 0.0);
    collision.environment().AddEllipsoid("bush", Eigen::Vector3d(0.3, 0.3, 0.35),
                                         Eigen::Isometry3d(Eigen::Translation3d(1.25, 0.0, 0.45)));
  }
  static Eigen::VectorXd Home() {
    const auto p = robot::RobotParameters::Load(testing::SourcePath("robot/config/robot_parameters.yaml"));
    return Eigen::Map<const Eigen::VectorXd>(p.arm_home_position.data(), 6);
  }
};

// Collision-free configurations around the bush's near side, from a fixed generator.
std::vector<Eigen::VectorXd> TargetsNearTheBush(const Fixture& f, int count) {
  std::uint64_t state = 99;
  auto uniform = [&]() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / static_cast<double>(1ULL << 53);
  };
  std::vector<Eigen::VectorXd> targets;
  while (static_cast<int>(targets.size()) < count) {
    Eigen::VectorXd q(6);
    for (int i = 0; i < 6; ++i) {
      const JointLimit& limit = f.kinematics.limits()[static_cast<size_t>(i)];
      q(i) = limit.continuous ? -M_PI + 2.0 * M_PI * uniform() : limit.lower + (limit.upper - limit.lower) * uniform();
    }
    const Eigen::Vector3d cutter = f.kinematics.EndEffectorPose(q).translation();
    const double to_bush =
        (cutter - Eigen::Vector3d(1.25, 0.0, 0.45)).cwiseQuotient(Eigen::Vector3d(0.3, 0.3, 0.35)).norm();
    if (to_bush < 1.6 && !f.collision.Check(q).collision) targets.push_back(q);
  }
  return targets;
}

// Every sample of the trajectory, and the straight joint-space steps between samples, is free.
void ExpectFreeAndWithinLimits(const Fixture& f, const ArmPlan& plan, double velocity_scale) {
  const auto& t = plan.trajectory;
  ASSERT_FALSE(t.positions.empty());
  for (size_t k = 0; k < t.positions.size(); ++k) {
    ASSERT_FALSE(f.collision.Check(t.positions[k]).collision) << "sample " << k;
    for (int i = 0; i < 6; ++i) {
      EXPECT_LE(std::abs(t.velocities[k](i)),
                velocity_scale * f.kinematics.limits()[static_cast<size_t>(i)].velocity + 1e-9);
    }
    EXPECT_TRUE(f.kinematics.WithinLimits(t.positions[k]));
  }
}

TEST(ArmPlanner, ReachesPosesAroundABushWithoutCollision) {
  Fixture f;
  ArmPlanner planner(f.kinematics, f.collision, {});
  int reached = 0;
  const auto targets = TargetsNearTheBush(f, 20);
  for (const Eigen::VectorXd& q : targets) {
    const Eigen::Isometry3d cutter = f.kinematics.EndEffectorPose(q);
    const ArmPlan plan = planner.PlanToPose(f.home, cutter);
    if (!plan.ok) {
      ADD_FAILURE() << plan.failure;
      continue;
    }
    ++reached;
    ExpectFreeAndWithinLimits(f, plan, planner.parameters().velocity_scale);
    const Eigen::Isometry3d end = f.kinematics.EndEffectorPose(plan.trajectory.positions.back());
    EXPECT_LT((end.translation() - cutter.translation()).norm(), 1e-5);
    EXPECT_LT(Eigen::AngleAxisd(end.linear().transpose() * cutter.linear()).angle(), 1e-5);
    EXPECT_GE(plan.free_goals, 1);
    EXPECT_GE(plan.ik_solutions, plan.free_goals);
    EXPECT_NEAR((plan.trajectory.positions.front() - f.home).norm(), 0.0, 1e-12);  // unwrapped from the start
  }
  EXPECT_EQ(reached, 20);
}

TEST(ArmPlanner, PosesItCannotReachFailWithTheReason) {
  Fixture f;
  ArmPlanner planner(f.kinematics, f.collision, {});
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() << 2.5, 0.0, 0.5;
  const ArmPlan out_of_reach = planner.PlanToPose(f.home, far);
  EXPECT_FALSE(out_of_reach.ok);
  EXPECT_NE(out_of_reach.failure.find("unreachable"), std::string::npos) << out_of_reach.failure;
  // Inside the bush: reachable (a pose of some configuration), but every solution collides.
  Eigen::Isometry3d inside = Eigen::Isometry3d::Identity();
  std::uint64_t state = 5;
  for (bool found = false; !found;) {
    Eigen::VectorXd q(6);
    for (int i = 0; i < 6; ++i) {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      const double u = static_cast<double>(state >> 11) / static_cast<double>(1ULL << 53);
      const JointLimit& limit = f.kinematics.limits()[static_cast<size_t>(i)];
      q(i) = limit.continuous ? -M_PI + 2.0 * M_PI * u : limit.lower + (limit.upper - limit.lower) * u;
    }
    inside = f.kinematics.EndEffectorPose(q);
    found = (inside.translation() - Eigen::Vector3d(1.25, 0.0, 0.45))
                .cwiseQuotient(Eigen::Vector3d(0.3, 0.3, 0.35))
                .norm() < 0.8;
  }
  const ArmPlan blocked = planner.PlanToPose(f.home, inside);
  EXPECT_FALSE(blocked.ok);
  EXPECT_NE(blocked.failure.find("collide"), std::string::npos) << blocked.failure << " " << blocked.ik_solutions;
}

TEST(ArmPlanner, CartesianPassKeepsTheCutterOnTheLine) {
  Fixture f;
  ArmPlanner planner(f.kinematics, f.collision, {});
  const auto targets = TargetsNearTheBush(f, 10);
  int passes = 0;
  for (const Eigen::VectorXd& q : targets) {
    const Eigen::Isometry3d from = f.kinematics.EndEffectorPose(q);
    Eigen::Isometry3d to = from;
    to.translation() += 0.08 * from.linear().col(0);  // sideways across the cutter's face
    const ArmPlan pass = planner.CartesianPass(q, to);
    if (!pass.ok) {  // a pass may run into a limit, a singularity or a branch switch; it must say which
      EXPECT_TRUE(pass.failure.find("inverse kinematics lost the line at") == 0 ||
                  pass.failure.find("the arm would switch branch at") == 0 || pass.failure.find("collision") == 0)
          << pass.failure;
      continue;
    }
    ++passes;
    ExpectFreeAndWithinLimits(f, pass, planner.parameters().velocity_scale);
    for (const Eigen::VectorXd& p : pass.trajectory.positions) {
      const Eigen::Vector3d c = f.kinematics.EndEffectorPose(p).translation();
      const Eigen::Vector3d d = (to.translation() - from.translation()).normalized();
      EXPECT_LT(((c - from.translation()) - d * d.dot(c - from.translation())).norm(), 2e-3);
    }
    const Eigen::Isometry3d end = f.kinematics.EndEffectorPose(pass.trajectory.positions.back());
    EXPECT_LT((end.translation() - to.translation()).norm(), 1e-5);
    EXPECT_NEAR(pass.cutter_path_length, 0.08, 0.004);
  }
  EXPECT_GE(passes, 5);  // 6 of these 10 random passes (8 cm across the cutter's face) stay on one branch
}

TEST(ArmPlanner, RoadmapIsReusedAcrossQueriesNearOneBush) {
  Fixture f;
  ArmPlannerParameters parameters;
  parameters.algorithm = ArmPlannerParameters::Algorithm::kLazyPrm;
  ArmPlanner planner(f.kinematics, f.collision, parameters);
  Eigen::VectorXd at = f.home;
  int reached = 0;
  for (const Eigen::VectorXd& q : TargetsNearTheBush(f, 10)) {
    const ArmPlan plan = planner.PlanToJoints(at, q);
    if (!plan.ok) {
      ADD_FAILURE() << plan.failure;
      continue;
    }
    ExpectFreeAndWithinLimits(f, plan, parameters.velocity_scale);
    at = plan.trajectory.positions.back();
    ++reached;
  }
  EXPECT_EQ(reached, 10);
}

TEST(ArmPlanner, TimingStartsAndEndsAtRestWithinTheLimits) {
  const std::vector<Eigen::VectorXd> path = {Eigen::VectorXd::Zero(2), (Eigen::VectorXd(2) << 1.0, 0.2).finished(),
                                             (Eigen::VectorXd(2) << 1.0, -0.5).finished()};
  const Eigen::VectorXd limits = (Eigen::VectorXd(2) << 0.5, 0.3).finished();
  const JointTrajectory t = TimeParameterize(path, limits, 1.0);
  EXPECT_EQ(t.positions.front(), path.front());
  EXPECT_LT((t.positions.back() - path.back()).norm(), 1e-12);
  EXPECT_LT(t.velocities.front().norm(), 1e-12);
  EXPECT_LT(t.velocities.back().norm(), 1e-12);
  for (size_t k = 0; k < t.times.size(); ++k) {
    EXPECT_LE(std::abs(t.velocities[k](0)), 0.5 + 1e-9);
    EXPECT_LE(std::abs(t.velocities[k](1)), 0.3 + 1e-9);
  }
  // Joint 0 is the slow one on the first segment: 1 rad at 0.5 rad/s and 1 rad/s^2 takes 2.5 s.
  // The second: joint 1 moves 0.7 rad at 0.3 rad/s: 0.7 / 0.3 + 0.3 = 2.633 s.
  EXPECT_NEAR(t.duration(), 2.5 + 0.7 / 0.3 + 0.3, 1e-9);
}

TEST(ArmPlanner, TimingPassesThroughWaypointsThatAreNoStops) {
  // A line of 1 rad in four steps, stopping at its ends only, takes as long as the line in one:
  // 2.5 s (above), and passes the middle at speed; stopping at every step takes longer.
  std::vector<Eigen::VectorXd> line;
  for (int k = 0; k <= 4; ++k) line.push_back((Eigen::VectorXd(2) << 0.25 * k, 0.0).finished());
  const Eigen::VectorXd limits = (Eigen::VectorXd(2) << 0.5, 0.3).finished();
  const JointTrajectory through = TimeParameterize(line, limits, 1.0, {true, false, false, false, true});
  EXPECT_NEAR(through.duration(), 2.5, 1e-9);
  Eigen::VectorXd q, v;
  through.Sample(1.25, &q, &v);
  EXPECT_NEAR(q(0), 0.5, 1e-9);
  EXPECT_NEAR(v(0), 0.5, 1e-9);
  EXPECT_GT(TimeParameterize(line, limits, 1.0).duration(), 3.9);  // four stops: 4 x 2 sqrt(0.25) = 4 s
  EXPECT_THROW(TimeParameterize(line, limits, 1.0, {true, false}), std::invalid_argument);
}

}  // namespace
}  // namespace trimbot::arm
