#pragma once
// Precomputed cutting paths, the real robot's speed-up (reference deliverable D3.4, Section 1.5:
// precomputed GTSP solutions retrieved from a database and optimized locally, minutes down to
// seconds). One SQLite file holds cutting paths solved in full for targets over a grid of shapes,
// sizes and placements relative to the base. At run time the stored path of the nearest target is
// adapted to the fitted one: each blade pose moved onto the fitted surface along its direction
// from the centre, the arm's solution found from the stored one (inverse kinematics from that
// seed alone, or another where the move there is refused), poses that no longer fit dropped, the
// order kept.
#include <Eigen/Geometry>
#include <functional>
#include <string>
#include <vector>

#include "trimbot/trimming/cutting_path.h"

namespace trimbot::trimming {

struct StoredCuttingPath {
  perception::TopiaryShape target;              // in base_link, as planned
  std::vector<Eigen::Isometry3d> blades;        // blade poses in visiting order
  std::vector<Eigen::VectorXd> configurations;  // the arm's solution of each
  double motion_time = 0.0;                     // s, with the moves from and back to the start
};

// What a stored path was planned for: the arm's joints, limits and geometry (its cutter pose at
// zero joint positions) and the blade on the cutter. A file made for another arm is refused.
std::string ArmSignature(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade);

class CuttingPathDatabase {
 public:
  static constexpr int kFormatVersion = 1;

  void Add(StoredCuttingPath path) { paths_.push_back(std::move(path)); }
  int size() const { return static_cast<int>(paths_.size()); }
  const StoredCuttingPath& path(int i) const { return paths_[static_cast<std::size_t>(i)]; }

  // Written atomically; std::runtime_error naming the file when it cannot be.
  void Save(const std::string& path, const std::string& arm_signature) const;
  // InputError naming the file: missing, not a cutting path database, another format version,
  // made for another arm, or rows that do not add up.
  static CuttingPathDatabase Load(const std::string& path, const std::string& expected_arm_signature);

  // The stored path whose target is nearest `target` among those of the same exponents (distance:
  // centres' plus semi-axes' differences plus the yaw's at the mean semi-axis, m, the yaw's modulo
  // the turns that leave the shapes as they are: any for a round plan, within the cut's 2 cm);
  // nullptr when the database holds none of that shape.
  const StoredCuttingPath* Nearest(const perception::TopiaryShape& target, double* distance = nullptr) const;

 private:
  std::vector<StoredCuttingPath> paths_;
};

// The stored path of a solved one (its blades, configurations and time).
StoredCuttingPath ToStored(const CuttingPath& path, const perception::TopiaryShape& target);

// The stored path adapted to `surface`, as described above. Where the move from the previous pose
// to a pose's solution near the stored one is refused, the pose takes the solution with the quickest
// free move (counted in refused_moves), else the valid one nearest in time, the move to it planned
// round the target (as a tour's refused move is); a pose with no valid solution is left out (in
// `unreachable`, by its index in the stored path). Not ok when no pose fits: plan in full then.
CuttingPath AdaptCuttingPath(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade,
                             const Eigen::VectorXd& start, const StoredCuttingPath& stored, const BladeSurface& surface,
                             const std::function<bool(const Eigen::VectorXd&)>& valid,
                             const std::function<bool(const Eigen::VectorXd&, const Eigen::VectorXd&)>& free_move,
                             const CuttingPathOptions& options = {});

}  // namespace trimbot::trimming
