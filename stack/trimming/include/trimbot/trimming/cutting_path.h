#pragma once
// The cutting path over a topiary's target shape (reference deliverable D3.4, Section 1.5): blade
// poses tangent to the target where the arm can reach it from where the base stands, the arm's
// collision-free inverse-kinematics solutions of each pose as one GTSP cluster (the blade spins,
// so its roll about its axis is free: several rolls per pose), the edge cost the time of a
// rest-to-rest joint move between two solutions, and a tour through one solution of every pose.
// Moves between blade poses are straight joint moves, or else straight blade moves (BladeLine: the
// blade along the line between them, as a hand would guide a hedge trimmer), where the collision
// check lets them be; where it refuses both, the arm planner plans it round obstacles, costed as the way through the
// start, and the tour is solved again (lazy edge checking: only the moves a tour makes, and their poses' other
// solutions, are checked). The moves from the start and back are the planner's too. A tour's cost
// counts each blade move as the straight joint move between its ends.
#include <Eigen/Geometry>
#include <functional>
#include <string>
#include <vector>

#include "trimbot/arm/arm_kinematics.h"
#include "trimbot/arm/arm_planner.h"
#include "trimbot/perception/topiary_fit.h"
#include "trimbot/robot/collision_model.h"
#include "trimbot/trimming/gtsp.h"

namespace trimbot::trimming {

struct CuttingPoseOptions {
  double spacing = 0.08;          // m between neighbouring blade centres on the target (the blade's
                                  // 0.1 m disc, overlapping)
  double max_facing_angle = 1.4;  // rad: surface whose normal turns further from the base is left
                                  // to another standoff
  double min_height = 0.05;       // m above the ground for the blade's centre
};

// Outward unit normal of the target at a point near its surface: the gradient of the radial
// distance, by central differences (the superellipsoid's own gradient, up to its length).
Eigen::Vector3d SurfaceNormal(const perception::TopiaryShape& target, const Eigen::Vector3d& p);

// The blade pose on the target's surface along a unit direction from its centre (both in the
// target's frame, base_link): the disc's centre on the surface, its z axis into it along the inward
// normal, its x axis `x_hint` made tangent (or any tangent when `x_hint` is zero or normal).
Eigen::Isometry3d BladePoseAt(const perception::TopiaryShape& target, const Eigen::Vector3d& direction,
                              const Eigen::Vector3d& x_hint = Eigen::Vector3d::Zero());

// `target` with its semi-axes moved `offset` outward (negative: inward, to 1 mm at least): on a box's
// faces that moves the surface along its normal, where a move along the radii would move an oblique
// part of a face by less. The surface the blade is aimed at and the collision checks' are both this.
perception::TopiaryShape Offset(const perception::TopiaryShape& target, double offset);

// Where the blade is aimed: `depth` inside the fitted target where the scan saw the leaves over
// it, on the fit itself where it did not. The fit is the quantile of the leaf points' distances;
// where there are none (a box's top, which the ring at 0.49 m sees edge-on) it is the shape's
// extrapolation from the faces beside, no bound of the target under it.
struct BladeSurface {
  // Aimed on `target` everywhere (a target known as it is: planning offline, tests).
  BladeSurface(const perception::TopiaryShape& target) : fit(target) {}  // NOLINT: implicit on purpose
  BladeSurface(const perception::TopiaryShape& fit, double depth, std::function<bool(const Eigen::Vector3d&)> seen)
      : fit(fit), depth(depth), seen(std::move(seen)) {}
  perception::TopiaryShape fit;
  double depth = 0.0;                                // m inside the fit where seen
  std::function<bool(const Eigen::Vector3d&)> seen;  // by the unit direction from the centre; unset: all
  perception::TopiaryShape aimed() const { return Offset(fit, -depth); }  // where it is seen
  // BladePoseAt on the aimed surface, or on the fit where the direction was not seen.
  Eigen::Isometry3d PoseAt(const Eigen::Vector3d& direction,
                           const Eigen::Vector3d& x_hint = Eigen::Vector3d::Zero()) const;
};

// Blade poses over the surface, facing the base at the origin: surface turned at most
// max_facing_angle from the base, and the crown's sector on the base's side (within 45 deg of its
// bearing; the crown, surface turned up more than sideways, faces no standoff).
std::vector<Eigen::Isometry3d> CuttingPoses(const BladeSurface& surface, const CuttingPoseOptions& options = {});

struct CuttingPathOptions {
  int rolls = 6;                // blade rolls about its axis tried per pose
  double velocity_scale = 0.5;  // of the URDF's joint velocity limits (as the arm planner's)
  double acceleration = 1.5;    // rad/s^2 per joint (as the arm planner's)
  int max_lazy_rounds = 30;     // tours solved again after refused moves, at most
  GtspSearchOptions search;
  arm::IkOptions ik;
};

struct CuttingPath {
  bool ok = false;
  std::string failure;                          // when not ok
  std::vector<Eigen::VectorXd> configurations;  // start, then one per reached pose in visiting order, then start
  std::vector<int> poses;                       // the pose of each configuration between start and end
  std::vector<Eigen::Isometry3d> blades;        // and its blade pose (the roll the arm's solution has)
  std::vector<bool> planned;            // per move (configuration i to i + 1): for the arm planner to plan round
                                        // obstacles (from and back to the start, and where a straight move is refused)
  std::vector<int> unreachable;         // poses with no collision-free solution
  double motion_time = 0.0;             // s: rest-to-rest joint moves along the tour
  double nearest_neighbour_time = 0.0;  // s: the greedy baseline's tour on the same instance
  int clusters = 0, nodes = 0;          // of the GTSP
  int refused_moves = 0;                // straight moves the collision check refused
};

// Time of a joint move from rest to rest along a straight joint-space line (trapezoidal speed
// profile, the slowest joint sets it; continuous joints the short way round).
double JointMoveTime(const arm::ArmKinematics& kinematics, const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                     double velocity_scale, double acceleration);

// The arm's collision model's environment: the ground and Offset(target, offset) as a solid convex
// polyhedron.
void SetTargetEnvironment(robot::CollisionModel* collision, const perception::TopiaryShape& target, double offset);

// How deep into the target the collision checks let the blade go: as deep as it is aimed
// (`aimed_depth`, its disc's mid-plane, where the blade cuts), half the disc's thickness (its
// collision cylinder's lower face), plus the sagitta of a straight blade move between neighbouring poses over the
// target's smallest semi-axis (where a ball or the rim of a cylinder curves most). Neighbours: the
// poses' lattice holds one per spacing^2 of surface, hexagonal neighbours sqrt(2 / sqrt(3)) spacing
// apart. A move that dips further (one that skips a pose) is refused and planned round. Not the
// 2 cm of the cut criterion: a blade let that deep cuts into the target wherever the fit stands
// less than 2 cm over it (docs/design.md, Trimming).
double CheckDepth(const perception::TopiaryShape& target, double aimed_depth, double spacing, double blade_thickness);

// The blade's straight move from configuration `a` to `b`: the blade's disc (`T_cutter_blade` in
// the cutter frame) along the line between where a and b put it (PosesAlongLine, the arm's
// cartesian_step), the arm following on a's branch by inverse kinematics from each step to the
// next. The configurations after `a`, the last one `b` (continuous joints unwrapped along the
// way); empty when the arm loses the line, would switch branch (a step over
// cartesian_max_joint_step), arrives at another solution than b, or `valid` (when given) refuses a
// configuration on the way (checked collision_step apart in joint space, as any motion is: a step
// near the wrist's singularity turns a joint up to cartesian_max_joint_step).
std::vector<Eigen::VectorXd> BladeLine(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade,
                                       const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                       const arm::ArmPlannerParameters& arm_parameters,
                                       const std::function<bool(const Eigen::VectorXd&)>& valid = {});

// The collision checks of a cutting path on the arm's collision model, whose environment becomes
// the ground and the target shrunk by `depth` (CheckDepth) as a solid (convex) polyhedron: the
// blade may go that deep. `also_valid`, when given, is a further condition on each configuration
// (the executive's: no arm link but the cutter's in the leaves the scan saw). A move between two
// configurations is the straight joint move where its configurations collision_step apart (rad,
// continuous joints the short way round) are valid, else the blade line (BladeLine) where its
// configurations are.
struct CuttingChecks {
  std::function<bool(const Eigen::VectorXd&)> valid;
  // The configurations of the move from a to b after a (the last b, unwrapped from a), checked;
  // empty when neither move is free.
  std::function<std::vector<Eigen::VectorXd>(const Eigen::VectorXd&, const Eigen::VectorXd&)> way;
  std::function<bool(const Eigen::VectorXd&, const Eigen::VectorXd&)> free_move;  // !way(a, b).empty()
};
CuttingChecks MakeCuttingChecks(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade,
                                robot::CollisionModel* collision, const perception::TopiaryShape& target, double depth,
                                const arm::ArmPlannerParameters& arm_parameters = {},
                                const std::function<bool(const Eigen::VectorXd&)>& also_valid = {});

// `valid(q)`: the configuration is free; `free_move(a, b)`: the move from a to b is (CuttingChecks::way).
// `T_cutter_blade`: the blade's disc in the cutter frame (from the URDF).
CuttingPath PlanCuttingPath(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade,
                            const Eigen::VectorXd& start, const std::vector<Eigen::Isometry3d>& blade_poses,
                            const std::function<bool(const Eigen::VectorXd&)>& valid,
                            const std::function<bool(const Eigen::VectorXd&, const Eigen::VectorXd&)>& free_move,
                            const CuttingPathOptions& options = {});

}  // namespace trimbot::trimming
