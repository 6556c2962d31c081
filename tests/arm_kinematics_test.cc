// The arm's kinematics from the URDF (KDL) against MuJoCo's model of the same robot, the Jacobian
// against finite differences, and the limits as the URDF gives them.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "sim_test_support.h"
#include "trimbot/arm/arm_kinematics.h"
#include "trimbot/common/input_error.h"
#include "trimbot/sim/world.h"

namespace trimbot::arm {
namespace {

// Deterministic joint positions: within the limits, continuous joints over a full turn and more.
class Configurations {
 public:
  explicit Configurations(const ArmKinematics& arm) : arm_(arm) {}
  Eigen::VectorXd Next() {
    Eigen::VectorXd q(arm_.joints());
    for (int i = 0; i < arm_.joints(); ++i) {
      const JointLimit& limit = arm_.limits()[static_cast<std::size_t>(i)];
      const double u = Uniform();
      q(i) = limit.continuous ? -2.0 * M_PI + 4.0 * M_PI * u : limit.lower + (limit.upper - limit.lower) * u;
    }
    return q;
  }

 private:
  double Uniform() {
    state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state_ >> 11) / static_cast<double>(1ULL << 53);
  }
  const ArmKinematics& arm_;
  std::uint64_t state_ = 2020;
};

Eigen::Isometry3d Pose(const mjtNum* pos, const mjtNum* mat) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() << pos[0], pos[1], pos[2];
  pose.linear() << mat[0], mat[1], mat[2], mat[3], mat[4], mat[5], mat[6], mat[7], mat[8];
  return pose;
}

TEST(ArmKinematics, ForwardKinematicsMatchesMujocoOverAThousandConfigurations) {
  sim::Simulator simulator(testing::TestConfig(testing::TestLawn(), "arm_fk"));
  const ArmKinematics arm(simulator.robot());
  ASSERT_EQ(arm.joints(), 6);
  sim::World& world = simulator.world();
  const mjModel* m = world.model();
  mjData* d = world.data();
  Configurations configurations(arm);
  double worst_position = 0.0, worst_angle = 0.0;
  int compared = 0;
  for (int n = 0; n < 1000; ++n) {
    const Eigen::VectorXd q = configurations.Next();
    for (int i = 0; i < 6; ++i) d->qpos[world.arm()[static_cast<std::size_t>(i)].qpos] = q(i);
    mj_kinematics(m, d);
    const Eigen::Isometry3d T_base_world =
        Pose(d->xpos + 3 * world.base_body(), d->xmat + 9 * world.base_body()).inverse();
    const std::vector<Eigen::Isometry3d> poses = arm.LinkPoses(q);
    for (std::size_t k = 0; k < arm.links().size(); ++k) {
      const int body = mj_name2id(m, mjOBJ_BODY, arm.links()[k].c_str());
      const int site = mj_name2id(m, mjOBJ_SITE, arm.links()[k].c_str());
      if (body < 0 && site < 0) continue;
      const Eigen::Isometry3d mujoco =
          T_base_world * (body >= 0 ? Pose(d->xpos + 3 * body, d->xmat + 9 * body)
                                    : Pose(d->site_xpos + 3 * site, d->site_xmat + 9 * site));
      worst_position = std::max(worst_position, (mujoco.translation() - poses[k].translation()).norm());
      worst_angle = std::max(worst_angle, Eigen::AngleAxisd(mujoco.linear().transpose() * poses[k].linear()).angle());
      ++compared;
    }
    ASSERT_LT((arm.EndEffectorPose(q).matrix() - poses.back().matrix()).norm(), 1e-12);
  }
  EXPECT_GE(compared, 1000 * 7) << "the arm's links and the cutter frame are in the MuJoCo model";
  EXPECT_LT(worst_position, 1e-6);
  EXPECT_LT(worst_angle, 1e-6);
}

TEST(ArmKinematics, JacobianMatchesFiniteDifferences) {
  const ArmKinematics arm(robot::RobotDescription::Load(testing::SourcePath("robot/urdf/trimbot.urdf")));
  Configurations configurations(arm);
  for (int n = 0; n < 50; ++n) {
    const Eigen::VectorXd q = configurations.Next();
    const Eigen::Matrix<double, 6, Eigen::Dynamic> J = arm.Jacobian(q);
    const Eigen::Isometry3d T = arm.EndEffectorPose(q);
    const double h = 1e-7;
    for (int i = 0; i < arm.joints(); ++i) {
      Eigen::VectorXd moved = q;
      moved(i) += h;
      const Eigen::Isometry3d Tm = arm.EndEffectorPose(moved);
      const Eigen::Vector3d v = (Tm.translation() - T.translation()) / h;
      const Eigen::AngleAxisd turn(Tm.linear() * T.linear().transpose());
      const Eigen::Vector3d w = turn.axis() * turn.angle() / h;
      EXPECT_LT((J.col(i).head<3>() - v).norm(), 1e-5) << "joint " << i;
      EXPECT_LT((J.col(i).tail<3>() - w).norm(), 1e-5) << "joint " << i;
    }
    EXPECT_GT(arm.Manipulability(q), 0.0);
  }
}

TEST(ArmKinematics, LimitsComeFromTheUrdf) {
  const ArmKinematics arm(robot::RobotDescription::Load(testing::SourcePath("robot/urdf/trimbot.urdf")));
  const std::vector<JointLimit>& limits = arm.limits();
  ASSERT_EQ(limits.size(), 6u);
  EXPECT_TRUE(limits[0].continuous);
  EXPECT_FALSE(limits[1].continuous);
  EXPECT_NEAR(limits[1].lower, 0.8203, 1e-9);
  EXPECT_NEAR(limits[1].upper, 5.4629, 1e-9);
  EXPECT_NEAR(limits[2].lower, 0.3316, 1e-9);
  EXPECT_NEAR(limits[0].velocity, 0.628, 1e-9);
  EXPECT_NEAR(limits[5].velocity, 0.838, 1e-9);
  Eigen::VectorXd q = Eigen::VectorXd::Constant(6, 3.0);
  EXPECT_TRUE(arm.WithinLimits(q));
  q(1) = 0.5;  // below joint 2's lower limit
  EXPECT_FALSE(arm.WithinLimits(q));
  EXPECT_THROW(arm.EndEffectorPose(Eigen::VectorXd::Zero(5)), std::invalid_argument);
}

// Poses the arm reaches (forward kinematics of random joint positions within the limits): IK finds
// a solution for nearly all, each solution puts the cutter at the pose, and the branch the pose
// came from is among them (a missed branch would show here: every configuration is some branch).
TEST(ArmKinematics, InverseKinematicsFindsTheBranchThePoseCameFrom) {
  const ArmKinematics arm(robot::RobotDescription::Load(testing::SourcePath("robot/urdf/trimbot.urdf")));
  Configurations configurations(arm);
  const int poses = 200;
  int solved = 0, branch_found = 0;
  double branches = 0.0;
  for (int n = 0; n < poses; ++n) {
    Eigen::VectorXd q = configurations.Next();
    for (int i = 0; i < 6; ++i) {
      if (arm.limits()[static_cast<std::size_t>(i)].continuous) q(i) = -std::remainder(-q(i), 2.0 * M_PI);
    }
    const Eigen::Isometry3d target = arm.EndEffectorPose(q);
    const IkResult result = arm.InverseKinematics(target);
    if (result.solutions.empty()) continue;
    ++solved;
    branches += static_cast<double>(result.solutions.size());
    bool found = false;
    for (const Eigen::VectorXd& s : result.solutions) {
      const Eigen::Isometry3d reached = arm.EndEffectorPose(s);
      EXPECT_LT((reached.translation() - target.translation()).norm(), 1e-6);
      EXPECT_TRUE(arm.WithinLimits(s));
      Eigen::VectorXd d = s - q;
      for (int i = 0; i < 6; ++i) d(i) = std::remainder(d(i), 2.0 * M_PI);
      found = found || d.cwiseAbs().maxCoeff() < 1e-3;
    }
    branch_found += found ? 1 : 0;
  }
  RecordProperty("solved", solved);
  RecordProperty("branch_found", branch_found);
  RecordProperty("mean_branches", std::to_string(branches / std::max(1, solved)));
  EXPECT_GE(solved, 0.99 * poses);
  EXPECT_GE(branch_found, 0.99 * poses);
  EXPECT_GT(branches / std::max(1, solved), 1.5) << "an offset-wrist 6R arm has several branches per pose";
}

// Every branch: the default seeding (pre-computed poses nearest the target, a few spread starts)
// finds every distinct solution that LM from 1024 starts spread densely over joint space finds.
TEST(ArmKinematics, InverseKinematicsFindsEveryBranchDenseSeedingFinds) {
  const ArmKinematics arm(robot::RobotDescription::Load(testing::SourcePath("robot/urdf/trimbot.urdf")));
  Configurations configurations(arm);
  IkOptions dense;
  dense.database_seeds = 0;
  dense.starts = 1024;
  int branches = 0, missed = 0;
  for (int n = 0; n < 40; ++n) {
    const Eigen::Isometry3d target = arm.EndEffectorPose(configurations.Next());
    const IkResult found = arm.InverseKinematics(target);
    for (const Eigen::VectorXd& s : arm.InverseKinematics(target, dense).solutions) {
      ++branches;
      const bool known = std::any_of(found.solutions.begin(), found.solutions.end(), [&](const Eigen::VectorXd& t) {
        Eigen::VectorXd d = s - t;
        for (int i = 0; i < 6; ++i) d(i) = std::remainder(d(i), 2.0 * M_PI);
        return d.cwiseAbs().maxCoeff() < 1e-3;
      });
      if (!known) ++missed;
    }
  }
  RecordProperty("branches", branches);
  EXPECT_GT(branches, 150);
  EXPECT_EQ(missed, 0);
}

// A pose out of reach fails with the reason, in bounded time.
TEST(ArmKinematics, UnreachablePoseFailsWithTheReason) {
  const ArmKinematics arm(robot::RobotDescription::Load(testing::SourcePath("robot/urdf/trimbot.urdf")));
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() << 3.0, 0.0, 0.5;
  const IkResult result = arm.InverseKinematics(far);
  EXPECT_TRUE(result.solutions.empty());
  EXPECT_NE(result.failure.find("unreachable"), std::string::npos) << result.failure;
}

}  // namespace
}  // namespace trimbot::arm
