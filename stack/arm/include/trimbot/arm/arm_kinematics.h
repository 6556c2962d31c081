#pragma once
// The Jaco's kinematics from the robot's URDF, the one source of truth: the chain from base_link
// to the cutter frame (arm_end_effector) as an Orocos KDL chain, the arm joints' limits and
// velocity limits, forward kinematics of every link of the chain, the geometric Jacobian,
// Yoshikawa's manipulability, and inverse kinematics returning every distinct solution of a cutter
// pose: the j2n6s300's offset wrist has no closed form, so Levenberg-Marquardt (KDL) from the
// nearest configurations of a database of pre-computed poses and from a fixed set of starts spread
// over joint space, continuous joints wrapped to (-pi, pi], solutions outside
// the limits dropped, the rest deduplicated. Angles in rad, lengths in m, poses in base_link.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/robot/robot_description.h"

namespace trimbot::arm {

struct JointLimit {
  std::string name;
  bool continuous = false;          // no position limits (the Jaco's joints 1, 4, 5, 6)
  double lower = 0.0, upper = 0.0;  // rad, when not continuous
  double velocity = 0.0;            // rad/s
};

struct IkOptions {
  // LM runs from the database's configurations whose poses are nearest the target (pre-computed
  // solutions, as on the real robot), then from fixed starts spread evenly over joint space.
  int database_seeds = 96;              // with 8 starts: every branch that 1024 starts find, on 200 random poses
  int database_size = 1 << 16;          // configurations in the database (built once, on first use)
  int starts = 8;                       // same pose, same answer
  double position_tolerance = 1e-6;     // m
  double orientation_tolerance = 1e-6;  // rad
  int max_iterations = 300;             // per start: bounded, so an unreachable pose fails, never hangs
  double distinct = 1e-3;               // rad: solutions closer than this in every joint are one
};

struct IkResult {
  std::vector<Eigen::VectorXd> solutions;  // distinct, within the limits, ordered by the first start that found them
  std::string failure;                     // when none: why (unreachable by how much, or only outside the limits)
};

struct SeedDatabase;

class ArmKinematics {
 public:
  // Throws InputError naming the URDF if the chain from base_link to arm_end_effector has a joint
  // type other than fixed, revolute or continuous, or not six moving joints.
  explicit ArmKinematics(const robot::RobotDescription& description);
  ~ArmKinematics();
  ArmKinematics(ArmKinematics&&) noexcept;
  ArmKinematics& operator=(ArmKinematics&&) noexcept;

  int joints() const { return static_cast<int>(limits_.size()); }
  const std::vector<JointLimit>& limits() const { return limits_; }
  // The links of the chain in order (each fixed or moving joint's child), base_link excluded.
  const std::vector<std::string>& links() const { return links_; }

  // The cutter frame in base_link for joint positions `q` (size joints()).
  Eigen::Isometry3d EndEffectorPose(const Eigen::VectorXd& q) const;
  // Every link of links() in base_link.
  std::vector<Eigen::Isometry3d> LinkPoses(const Eigen::VectorXd& q) const;
  // Geometric Jacobian of the cutter frame's origin: rows (v; w) in base_link, one column per joint.
  Eigen::Matrix<double, 6, Eigen::Dynamic> Jacobian(const Eigen::VectorXd& q) const;
  // sqrt(det(J J^T)): 0 at a singularity.
  double Manipulability(const Eigen::VectorXd& q) const;
  // `q` within the limits (continuous joints always are); std::invalid_argument for a wrong size.
  bool WithinLimits(const Eigen::VectorXd& q) const;
  // `to` - `from` per joint, the continuous joints the short way round (rad).
  Eigen::VectorXd JointDifference(const Eigen::VectorXd& from, const Eigen::VectorXd& to) const;
  // Every distinct joint solution that puts the cutter frame at `target` (base_link).
  IkResult InverseKinematics(const Eigen::Isometry3d& target, const IkOptions& options = {}) const;
  // Builds the database of pre-computed poses now (else the first InverseKinematics does).
  void PrepareDatabase(const IkOptions& options = {}) const { Database(options.database_size); }
  // The solution reached from `seed` alone (the branch the arm is on, for a small step of the
  // cutter), continuous joints left near the seed's values; nullopt when it misses the pose or a limit.
  std::optional<Eigen::VectorXd> InverseKinematicsNear(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed,
                                                       const IkOptions& options = {}) const;

 private:
  void CheckSize(const Eigen::VectorXd& q) const;
  const SeedDatabase& Database(int size) const;
  std::vector<Eigen::VectorXd> Seeds(const Eigen::Isometry3d& target, const IkOptions& options) const;

  struct Chain;
  std::unique_ptr<Chain> chain_;
  std::vector<JointLimit> limits_;
  std::vector<std::string> links_;
};

}  // namespace trimbot::arm
