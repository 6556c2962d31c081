// The arm's executive on its own: goals planned around perceived points, executed by a joint
// follower standing in for the arm's servos, judged by the encoders; a goal inside the bush is
// refused with the reason and the mission goes on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "test_support.h"
#include "trimbot/arm/arm_executive.h"
#include "trimbot/robot/robot_parameters.h"

namespace trimbot::arm {
namespace {

const Eigen::Vector3d kBushCentre(1.33, 0.0, 0.375);
const Eigen::Vector3d kBushRadii(0.4, 0.4, 0.375);

class Uniform {
 public:
  double operator()() {
    state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state_ >> 11) / static_cast<double>(1ULL << 53);
  }

 private:
  std::uint64_t state_ = 41;
};

// What stereo sees of the bush: the half facing the robot, 1 cm apart, 1 cm of noise.
std::vector<Eigen::Vector3d> SeenBush(Uniform& uniform) {
  std::vector<Eigen::Vector3d> points;
  for (double el = -1.2; el <= 1.4; el += 0.025) {
    for (double az = M_PI / 2; az <= 3 * M_PI / 2; az += 0.025) {
      const Eigen::Vector3d unit(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      points.push_back(kBushCentre + kBushRadii.cwiseProduct(unit) + 0.02 * (uniform() - 0.5) * unit);
    }
  }
  return points;
}

TEST(ArmExecutive, ReachesGoalsAroundWhatItSawAndRefusesOneInsideTheBush) {
  const robot::RobotDescription robot = robot::RobotDescription::Load(testing::SourcePath("robot/urdf/trimbot.urdf"));
  const ArmExecutiveParameters parameters;
  ArmExecutive executive(robot, parameters);
  const ArmKinematics kinematics(robot);
  Uniform uniform;
  const std::vector<Eigen::Vector3d> seen = SeenBush(uniform);
  // Goals the planner can accept (free in the perceived environment), but the second inside the bush.
  robot::CollisionModel perceived(robot, robot.ArmJointNames());
  BuildPerceivedEnvironment(robot, parameters, seen, {}, &perceived.environment());
  std::vector<Eigen::Isometry3d> goals;
  while (goals.size() < 4) {
    Eigen::VectorXd q(6);
    for (int i = 0; i < 6; ++i) {
      const JointLimit& limit = kinematics.limits()[static_cast<size_t>(i)];
      q(i) = limit.continuous ? -M_PI + 2 * M_PI * uniform() : limit.lower + (limit.upper - limit.lower) * uniform();
    }
    const Eigen::Isometry3d cutter = kinematics.EndEffectorPose(q);
    const double radius = (cutter.translation() - kBushCentre).cwiseQuotient(kBushRadii).norm();
    const bool inside_wanted = goals.size() == 1;  // a reachable pose with the cutter inside the bush
    if (inside_wanted ? radius < 0.95 : radius > 1.2 && radius < 1.5 && !perceived.Check(q).collision) {
      goals.push_back(cutter);
    }
  }
  // The true bush, to check every commanded configuration against.
  robot::CollisionModel truth(robot, robot.ArmJointNames());
  truth.environment().AddEllipsoid("bush", kBushRadii, Eigen::Isometry3d(Eigen::Translation3d(kBushCentre)));
  truth.environment().AddGround("ground", 0.0);

  executive.SetGoals(goals);
  EXPECT_TRUE(executive.WantsEnvironment());
  executive.SetPerceivedPoints(seen, {});
  EXPECT_FALSE(executive.WantsEnvironment());
  EXPECT_GT(executive.perceived_cells(), 500);
  const auto home =
      robot::RobotParameters::Load(testing::SourcePath("robot/config/robot_parameters.yaml")).arm_home_position;
  Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(home.data(), 6), target = q;
  std::vector<ArmGoalResult> results;
  const double dt = 0.01, lag = 0.1;  // s: the follower closes on its target with this time constant
  for (double t = 0.0; t < 300.0 && executive.mode() != ArmExecutive::Mode::kDone; t += dt) {
    q += (target - q) * (dt / lag);
    messages::ArmJointState joints;
    joints.stamp = t;
    for (int i = 0; i < 6; ++i) joints.position[static_cast<size_t>(i)] = q(i);
    executive.SetJointState(joints);
    if (const auto command = executive.Update(t)) {
      target = Eigen::Map<const Eigen::VectorXd>(command->position.data(), 6);
      ASSERT_FALSE(truth.Check(target).collision) << "commanded into the bush or the robot at t = " << t;
    }
    for (ArmGoalResult& result : executive.TakeResults()) results.push_back(result);
  }
  ASSERT_EQ(executive.mode(), ArmExecutive::Mode::kDone);
  ASSERT_EQ(results.size(), 4u);
  for (const ArmGoalResult& result : results) {
    if (result.goal == 1) {
      EXPECT_FALSE(result.reached);
      EXPECT_NE(result.failure.find("collide"), std::string::npos) << result.failure;
      continue;
    }
    EXPECT_TRUE(result.reached) << result.goal << ": " << result.failure;
    EXPECT_LT(result.position_error, 0.003);
    EXPECT_GT(result.tracking_error_max, 0.0);  // the follower lags its targets
    EXPECT_GT(result.motion_duration, 0.0);
  }
}

}  // namespace
}  // namespace trimbot::arm
