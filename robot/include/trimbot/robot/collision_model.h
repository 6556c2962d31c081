#pragma once
// The robot's collision geometry from the URDF, posed by joint positions, checked with FCL against
// itself and an environment: the one collision model the arm planner (stack/, environment from
// perception) and the evaluation (scenarios/, environment from the garden) both use.
//
// Self-collision skips the pairs the URDF's adjacency allows (the allowed-collision matrix): links
// joined rigidly (a chain of fixed joints: one rigid body) and links of rigid bodies joined by one
// moving joint (they touch at the joint by construction). Everything else is checked.
//
// Use:  CollisionModel model(description, description.ArmJointNames());
//       model.environment().AddEllipsoid("bush", radii, pose);  model.environment().AddGround(0.0);
//       model.Check(q)  ->  collision?, which pair, and (on request) the clearance.
// Poses are in base_link unless a base pose is given; lengths in m.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "trimbot/robot/robot_description.h"

namespace trimbot::robot {

// Objects the robot may hit, in one frame (the frame of the base pose given to the checks).
class CollisionEnvironment {
 public:
  CollisionEnvironment();
  ~CollisionEnvironment();
  CollisionEnvironment(CollisionEnvironment&&) noexcept;
  CollisionEnvironment& operator=(CollisionEnvironment&&) noexcept;

  void Clear();
  void AddBox(const std::string& name, const Eigen::Vector3d& size, const Eigen::Isometry3d& pose);
  void AddCylinder(const std::string& name, double radius, double length, const Eigen::Isometry3d& pose);  // axis z
  void AddEllipsoid(const std::string& name, const Eigen::Vector3d& radii, const Eigen::Isometry3d& pose);
  void AddSphere(const std::string& name, double radius, const Eigen::Vector3d& centre);
  // A triangle mesh (vertices in the mesh's frame, posed by `pose`).
  void AddMesh(const std::string& name, const std::vector<Eigen::Vector3d>& vertices,
               const std::vector<std::array<int, 3>>& triangles, const Eigen::Isometry3d& pose);
  // A solid convex polyhedron (vertices in this frame; faces outward-oriented triangles), e.g. the
  // convex hull a physics engine collides a mesh with.
  void AddConvex(const std::string& name, const std::vector<Eigen::Vector3d>& vertices,
                 const std::vector<std::array<int, 3>>& triangles);
  // Everything at or below z = height: the ground.
  void AddGround(const std::string& name, double height);
  // Occupied space seen as points (a perceived cloud): an octree of cubes of edge `resolution`, each
  // holding at least one point.
  void AddOccupiedPoints(const std::string& name, const std::vector<Eigen::Vector3d>& points, double resolution);

  int size() const;
  const std::string& name(int index) const;
  // Distance from a point to object `index` (0 when the point is inside a solid or touches it).
  double DistanceTo(int index, const Eigen::Vector3d& point) const;

 private:
  friend class CollisionModel;
  struct Objects;
  std::unique_ptr<Objects> objects_;
};

struct CollisionCheckOptions {
  bool self = true;         // robot against itself
  bool environment = true;  // the varied links against the environment
  bool distance = false;    // also the clearance (slower): min distance over the pairs checked
  // Links whose pose does not change with the varied joints are checked against the environment too
  // (off for arm planning, where the base stands where it is).
  bool static_links_against_environment = false;
};

struct CollisionReport {
  bool collision = false;
  std::pair<std::string, std::string> pair;  // the first pair found in contact ("link/#k" or environment name)
  // With options.distance: the smallest distance between the pairs checked (0 in contact), and its pair
  // (a pair with the robot's body: beyond its body clearance).
  double clearance = 0.0;
  std::pair<std::string, std::string> closest;
};

class CollisionModel {
 public:
  // Every <collision> (box, cylinder, sphere) of every link; `varied_joints` are the joints whose
  // positions the checks take (others stay at zero). A moving link and one of the robot's body (a
  // link the varied joints do not move: the base, the camera ring, the arm's mount) collide closer
  // than `body_clearance` (m): the margin a planner keeps for the arm's tracking error (the body's
  // boxes and cylinders grown by it on every side, so up to sqrt(3) times that at a corner). Throws
  // InputError naming the URDF for a mesh collision geometry or an unknown joint.
  CollisionModel(const RobotDescription& description, const std::vector<std::string>& varied_joints,
                 double body_clearance = 0.0);
  ~CollisionModel();
  CollisionModel(CollisionModel&&) noexcept;
  CollisionModel& operator=(CollisionModel&&) noexcept;

  CollisionEnvironment& environment() { return environment_; }
  const CollisionEnvironment& environment() const { return environment_; }

  // `q`: positions of the varied joints, in their order. `T_frame_base`: base_link in the
  // environment's frame.
  CollisionReport Check(const Eigen::VectorXd& q, const CollisionCheckOptions& options = {},
                        const Eigen::Isometry3d& T_frame_base = Eigen::Isometry3d::Identity()) const;

  // Links with collision geometry that move with the varied joints, and the self-collision pairs checked.
  const std::vector<std::string>& moving_links() const { return moving_link_names_; }
  const std::vector<std::pair<std::string, std::string>>& checked_pairs() const { return checked_pair_names_; }
  const std::vector<std::pair<std::string, std::string>>& allowed_pairs() const { return allowed_pair_names_; }

 private:
  struct Robot;
  std::unique_ptr<Robot> robot_;
  CollisionEnvironment environment_;
  std::vector<std::string> moving_link_names_;
  std::vector<std::pair<std::string, std::string>> checked_pair_names_;
  std::vector<std::pair<std::string, std::string>> allowed_pair_names_;
};

}  // namespace trimbot::robot
