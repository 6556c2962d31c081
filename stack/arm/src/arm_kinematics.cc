#include "trimbot/arm/arm_kinematics.h"

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include <Eigen/Eigenvalues>
#include <nanoflann.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "trimbot/common/input_error.h"
#include "trimbot/common/pose2.h"

namespace trimbot::arm {
namespace {

KDL::Frame ToKdl(const urdf::Pose& pose) {
  double x = 0, y = 0, z = 0, w = 1;
  pose.rotation.getQuaternion(x, y, z, w);
  return KDL::Frame(KDL::Rotation::Quaternion(x, y, z, w),
                    KDL::Vector(pose.position.x, pose.position.y, pose.position.z));
}

Eigen::Isometry3d ToEigen(const KDL::Frame& frame) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    pose.translation()(r) = frame.p(r);
    for (int c = 0; c < 3; ++c) pose.linear()(r, c) = frame.M(r, c);
  }
  return pose;
}

KDL::JntArray ToKdl(const Eigen::VectorXd& q) {
  KDL::JntArray array(static_cast<unsigned>(q.size()));
  array.data = q;
  return array;
}

KDL::Frame ToKdl(const Eigen::Isometry3d& pose) {
  KDL::Frame frame;
  for (int r = 0; r < 3; ++r) {
    frame.p(r) = pose.translation()(r);
    for (int c = 0; c < 3; ++c) frame.M(r, c) = pose.linear()(r, c);
  }
  return frame;
}

// A van der Corput / Halton sequence in [0, 1): deterministic starts spread evenly over joint space.
double Halton(int index, int base) {
  double result = 0.0, fraction = 1.0 / base;
  for (int i = index + 1; i > 0; i /= base, fraction /= base) result += fraction * (i % base);
  return result;
}

// A pose as a point for nearest-neighbour search: the position and two axes of the orientation
// scaled so that 1 rad weighs like 0.15 m.
constexpr double kOrientationWeight = 0.15;
std::array<double, 9> PoseFeature(const Eigen::Isometry3d& pose) {
  const Eigen::Vector3d& p = pose.translation();
  const Eigen::Vector3d x = kOrientationWeight * pose.linear().col(0), z = kOrientationWeight * pose.linear().col(2);
  return {p.x(), p.y(), p.z(), x.x(), x.y(), x.z(), z.x(), z.y(), z.z()};
}

}  // namespace

// Pre-computed solutions (the real robot's speed-up, D3.4 Section 1.5): joint configurations spread
// over joint space and the cutter pose of each, searched by pose. The configurations whose poses
// are nearest a target lie near its solutions, on every branch that reaches near it.
struct SeedDatabase {
  std::vector<Eigen::VectorXd> joints;
  std::vector<std::array<double, 9>> features;
  size_t kdtree_get_point_count() const { return features.size(); }
  double kdtree_get_pt(size_t i, size_t d) const { return features[i][d]; }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
};
using SeedTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, SeedDatabase>, SeedDatabase, 9>;

struct ArmKinematics::Chain {
  KDL::Chain chain;
  std::unique_ptr<KDL::ChainFkSolverPos_recursive> fk;
  std::unique_ptr<KDL::ChainJntToJacSolver> jacobian;
  std::unique_ptr<KDL::ChainIkSolverPos_LMA> ik;
  // Built on the first inverse kinematics that asks for database seeds.
  std::once_flag database_built;
  SeedDatabase database;
  std::unique_ptr<SeedTree> tree;
};

ArmKinematics::ArmKinematics(const robot::RobotDescription& description) : chain_(std::make_unique<Chain>()) {
  const urdf::ModelInterface& model = description.urdf();
  // The joints from the cutter frame up to base_link, then in order from the base (as kdl_parser
  // builds segments: the joint turns about its axis through the joint origin in the parent frame).
  std::vector<urdf::JointConstSharedPtr> path;
  for (auto link = model.getLink(robot::RobotFrames::kEndEffector); link && link->parent_joint;
       link = model.getLink(link->parent_joint->parent_link_name)) {
    path.push_back(link->parent_joint);
  }
  std::reverse(path.begin(), path.end());
  if (path.empty() || path.front()->parent_link_name != robot::RobotFrames::kBase) {
    throw InputError(description.path(), std::string("no chain from base_link to ") + robot::RobotFrames::kEndEffector);
  }
  for (const auto& joint : path) {
    const KDL::Frame origin = ToKdl(joint->parent_to_joint_origin_transform);
    KDL::Joint kdl_joint(joint->name, KDL::Joint::None);
    if (joint->type == urdf::Joint::REVOLUTE || joint->type == urdf::Joint::CONTINUOUS) {
      const KDL::Vector axis(joint->axis.x, joint->axis.y, joint->axis.z);
      kdl_joint = KDL::Joint(joint->name, origin.p, origin.M * axis, KDL::Joint::RotAxis);
      JointLimit limit;
      limit.name = joint->name;
      limit.continuous = joint->type == urdf::Joint::CONTINUOUS || !joint->limits;
      if (!limit.continuous) {
        limit.lower = joint->limits->lower;
        limit.upper = joint->limits->upper;
      }
      limit.velocity = joint->limits ? joint->limits->velocity : 0.0;
      if (limit.velocity <= 0.0)
        throw InputError(description.path(), "joint '" + joint->name + "' has no velocity limit");
      limits_.push_back(limit);
    } else if (joint->type != urdf::Joint::FIXED) {
      throw InputError(description.path(),
                       "joint '" + joint->name + "' of the arm chain is neither fixed nor revolute");
    }
    chain_->chain.addSegment(KDL::Segment(joint->child_link_name, kdl_joint, origin));
    links_.push_back(joint->child_link_name);
  }
  if (limits_.size() != 6) {
    throw InputError(description.path(),
                     "the arm chain has " + std::to_string(limits_.size()) + " moving joints, not 6");
  }
  chain_->fk = std::make_unique<KDL::ChainFkSolverPos_recursive>(chain_->chain);
  chain_->jacobian = std::make_unique<KDL::ChainJntToJacSolver>(chain_->chain);
}

ArmKinematics::~ArmKinematics() = default;
ArmKinematics::ArmKinematics(ArmKinematics&&) noexcept = default;
ArmKinematics& ArmKinematics::operator=(ArmKinematics&&) noexcept = default;

void ArmKinematics::CheckSize(const Eigen::VectorXd& q) const {
  if (q.size() != joints()) {
    throw std::invalid_argument("ArmKinematics: " + std::to_string(q.size()) + " joint positions for " +
                                std::to_string(joints()) + " joints");
  }
}

Eigen::Isometry3d ArmKinematics::EndEffectorPose(const Eigen::VectorXd& q) const {
  CheckSize(q);
  KDL::Frame frame;
  chain_->fk->JntToCart(ToKdl(q), frame);
  return ToEigen(frame);
}

std::vector<Eigen::Isometry3d> ArmKinematics::LinkPoses(const Eigen::VectorXd& q) const {
  CheckSize(q);
  const KDL::JntArray joints = ToKdl(q);
  std::vector<Eigen::Isometry3d> poses;
  for (int segment = 1; segment <= static_cast<int>(links_.size()); ++segment) {
    KDL::Frame frame;
    chain_->fk->JntToCart(joints, frame, segment);
    poses.push_back(ToEigen(frame));
  }
  return poses;
}

Eigen::Matrix<double, 6, Eigen::Dynamic> ArmKinematics::Jacobian(const Eigen::VectorXd& q) const {
  CheckSize(q);
  KDL::Jacobian jacobian(static_cast<unsigned>(joints()));
  chain_->jacobian->JntToJac(ToKdl(q), jacobian);
  return jacobian.data;
}

double ArmKinematics::Manipulability(const Eigen::VectorXd& q) const {
  const Eigen::Matrix<double, 6, Eigen::Dynamic> J = Jacobian(q);
  return std::sqrt(std::max(0.0, (J * J.transpose()).determinant()));
}

bool ArmKinematics::WithinLimits(const Eigen::VectorXd& q) const {
  CheckSize(q);
  for (int i = 0; i < joints(); ++i) {
    const JointLimit& limit = limits_[static_cast<std::size_t>(i)];
    if (!limit.continuous && (q(i) < limit.lower || q(i) > limit.upper)) return false;
  }
  return true;
}

Eigen::VectorXd ArmKinematics::JointDifference(const Eigen::VectorXd& from, const Eigen::VectorXd& to) const {
  CheckSize(from);
  CheckSize(to);
  Eigen::VectorXd d = to - from;
  for (int i = 0; i < joints(); ++i) {
    if (limits_[static_cast<std::size_t>(i)].continuous) d(i) = WrapAngle(d(i));
  }
  return d;
}

const SeedDatabase& ArmKinematics::Database(int size) const {
  std::call_once(chain_->database_built, [&] {
    static constexpr int kPrimes[6] = {17, 19, 23, 29, 31, 37};  // not the starts' primes
    SeedDatabase& database = chain_->database;
    for (int n = 0; n < size; ++n) {
      Eigen::VectorXd q(joints());
      for (int i = 0; i < joints(); ++i) {
        const JointLimit& limit = limits_[static_cast<std::size_t>(i)];
        const double u = Halton(n, kPrimes[i]);
        q(i) = limit.continuous ? -M_PI + 2.0 * M_PI * u : limit.lower + (limit.upper - limit.lower) * u;
      }
      database.features.push_back(PoseFeature(EndEffectorPose(q)));
      database.joints.push_back(std::move(q));
    }
    chain_->tree = std::make_unique<SeedTree>(9, database, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    chain_->tree->buildIndex();
  });
  return chain_->database;
}

std::vector<Eigen::VectorXd> ArmKinematics::Seeds(const Eigen::Isometry3d& target, const IkOptions& options) const {
  static constexpr int kPrimes[6] = {2, 3, 5, 7, 11, 13};
  std::vector<Eigen::VectorXd> seeds;
  if (options.database_seeds > 0) {
    const SeedDatabase& database = Database(options.database_size);
    const std::array<double, 9> query = PoseFeature(target);
    const size_t k = std::min<size_t>(static_cast<size_t>(options.database_seeds), database.joints.size());
    std::vector<unsigned> nearest(k);  // nanoflann's default index type
    std::vector<double> distances(k);
    const size_t found = chain_->tree->knnSearch(query.data(), k, nearest.data(), distances.data());
    for (size_t n = 0; n < found; ++n) seeds.push_back(database.joints[nearest[n]]);
  }
  for (int start = 0; start < options.starts; ++start) {
    Eigen::VectorXd q(joints());
    for (int i = 0; i < joints(); ++i) {
      const JointLimit& limit = limits_[static_cast<std::size_t>(i)];
      const double u = Halton(start, kPrimes[i]);
      q(i) = limit.continuous ? -M_PI + 2.0 * M_PI * u : limit.lower + (limit.upper - limit.lower) * u;
    }
    seeds.push_back(std::move(q));
  }
  return seeds;
}

IkResult ArmKinematics::InverseKinematics(const Eigen::Isometry3d& target, const IkOptions& options) const {
  KDL::ChainIkSolverPos_LMA solver(chain_->chain, 1e-12, options.max_iterations);
  const KDL::Frame goal = ToKdl(target);
  IkResult result;
  double closest_position = std::numeric_limits<double>::infinity(), closest_angle = closest_position;
  int outside_limits = 0;
  const std::vector<Eigen::VectorXd> seeds = Seeds(target, options);
  for (const Eigen::VectorXd& seed : seeds) {
    KDL::JntArray solution(static_cast<unsigned>(joints()));
    solver.CartToJnt(ToKdl(seed), goal, solution);
    Eigen::VectorXd q = solution.data;
    for (int i = 0; i < joints(); ++i) {
      if (limits_[static_cast<std::size_t>(i)].continuous) q(i) = -WrapAngle(-q(i));  // (-pi, pi]
    }
    const Eigen::Isometry3d reached = EndEffectorPose(q);
    const double position = (reached.translation() - target.translation()).norm();
    const double angle = Eigen::AngleAxisd(reached.linear().transpose() * target.linear()).angle();
    closest_position = std::min(closest_position, position);
    closest_angle = std::min(closest_angle, angle);
    if (position > options.position_tolerance || angle > options.orientation_tolerance) continue;
    if (!WithinLimits(q)) {
      ++outside_limits;
      continue;
    }
    const bool known = std::any_of(result.solutions.begin(), result.solutions.end(), [&](const Eigen::VectorXd& s) {
      return JointDifference(q, s).cwiseAbs().maxCoeff() < options.distinct;
    });
    if (!known) result.solutions.push_back(q);
  }
  if (result.solutions.empty()) {
    std::ostringstream why;
    if (outside_limits > 0) {
      why << "the pose is reached only outside the joint limits (" << outside_limits << " of " << seeds.size()
          << " starts)";
    } else {
      why << "unreachable: the closest of " << seeds.size() << " starts ends " << closest_position << " m and "
          << closest_angle * 180.0 / M_PI << " deg from the pose";
    }
    result.failure = why.str();
  }
  return result;
}

std::optional<Eigen::VectorXd> ArmKinematics::InverseKinematicsNear(const Eigen::Isometry3d& target,
                                                                    const Eigen::VectorXd& seed,
                                                                    const IkOptions& options) const {
  CheckSize(seed);
  // Gauss-Newton steps (slightly damped) from the seed first: for the small step of the cutter this
  // is for, two or three of them reach the tolerance, some ten times faster than KDL's
  // Levenberg-Marquardt, which takes over where they do not.
  constexpr int kNewtonSteps = 6;
  constexpr double kDamping = 1e-6;  // lambda^2 of the damped least squares
  Eigen::VectorXd near = seed;
  for (int step = 0; step < kNewtonSteps; ++step) {
    const Eigen::Isometry3d at = EndEffectorPose(near);
    const Eigen::AngleAxisd turn(target.linear() * at.linear().transpose());
    Eigen::Matrix<double, 6, 1> error;
    error << target.translation() - at.translation(), turn.angle() * turn.axis();
    if (error.head<3>().norm() <= options.position_tolerance && turn.angle() <= options.orientation_tolerance) {
      if (WithinLimits(near)) return near;
      break;
    }
    const Eigen::Matrix<double, 6, Eigen::Dynamic> J = Jacobian(near);
    near +=
        J.transpose() * (J * J.transpose() + kDamping * Eigen::Matrix<double, 6, 6>::Identity()).ldlt().solve(error);
  }
  KDL::ChainIkSolverPos_LMA solver(chain_->chain, 1e-12, options.max_iterations);
  KDL::JntArray solution(static_cast<unsigned>(joints()));
  solver.CartToJnt(ToKdl(seed), ToKdl(target), solution);
  const Eigen::VectorXd q = solution.data;
  const Eigen::Isometry3d reached = EndEffectorPose(q);
  if ((reached.translation() - target.translation()).norm() > options.position_tolerance ||
      Eigen::AngleAxisd(reached.linear().transpose() * target.linear()).angle() > options.orientation_tolerance ||
      !WithinLimits(q)) {
    return std::nullopt;
  }
  return q;
}

}  // namespace trimbot::arm
