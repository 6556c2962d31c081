#pragma once
// Trimming one topiary from where the base stands (the arm's part of a `trim` goal):
//
//   Start(expected)        the bush as the survey and the servo place it, in base_link
//     -> scan              one ring frame's stereo points (SetPerceivedPoints), from where the
//                          approach ended (the whole bush in view)
//     -> fit               the target shape into the points near the expected outline (FitTopiary)
//     -> StandsAt(motion)  the base has moved closer (the arm must reach round the bush): the fit
//                          is carried over by the base's motion
//     -> plan              the cutting path over the fitted target: the nearest stored path
//                          adapted (CuttingPathDatabase, when one is given and holds a target
//                          near enough) or solved in full (PlanCuttingPath)
//     -> cut               one joint trajectory through the path, the blade spinning; the moves
//                          the path leaves to the planner are planned round the target; the arm
//                          comes in to the first blade pose and leaves the last round the leaves
//                          as the scan saw them, then along the blade's axis (the blade cutting its
//                          way in and out)
//     -> done              the arm back at its start; report()
//
// The collision model's environment is the ground and the fitted target shrunk by as deep as the
// blade is aimed and a straight cut between its poses dips (CheckDepth, MakeCuttingChecks): the
// leaves outside it are what the blade is there to cut. For
// the moves in and out it is the target grown by the leaves' depth the scan measured, so no link
// but the blade goes into them. While cutting, the links but the cutter's keep out of those
// leaves too (ArmInLeaves). Nothing here sees ground truth.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "trimbot/arm/arm_planner.h"
#include "trimbot/messages/commands.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/perception/topiary_fit.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/trimming/cutting_path.h"
#include "trimbot/trimming/plan_database.h"

namespace trimbot::trimming {

struct TrimParameters {
  double surface_gap = 0.45;      // m from the surveyed outline to the arm's axis at the trim's standoff (the
                                  // base advances there from the approach's on odometry)
  double scan_margin = 0.25;      // m beyond the expected outline: stereo points this close are the bush's
  double min_height = 0.05;       // m above the ground: lower points are grass
  double max_point_sigma = 0.05;  // m: less certain stereo points are not used
  int max_points = 5000;          // more are thinned evenly (the fit's time is linear in them)
  // m: a point of an earlier scan this close to one of this scan is of a part this scan saw itself
  double scan_overlap = 0.05;
  perception::TopiaryFitOptions fit;
  CuttingPoseOptions poses;
  CuttingPathOptions path;
  double blade_depth = 0.01;            // m inside the fitted surface the blade is aimed at
  double leaf_quantile = 0.95;          // of the bush's points' distances outside the fit: the leaves' depth
  double leaf_clearance = 0.03;         // m kept from the leaves moving in and out
  double database_max_distance = 0.15;  // m: a stored target farther than this is solved in full
  arm::ArmPlannerParameters planner;    // the moves round the bush; its speeds time the whole cut
  double settle_tolerance = 0.002;      // rad
  double settle_timeout = 3.0;          // s

  // `path` with the planner's speeds and inverse kinematics: one speed model for the path's costs,
  // the trajectory that executes it and the stored paths of trimbot trim precompute.
  CuttingPathOptions PathOptions() const;
};

// How the trim went, as the stack knows it.
struct TrimReport {
  bool cut = false;               // the path was executed to its end
  std::string failure;            // when not: why (no points, no fit, nothing reachable, no move round the bush)
  double start = 0.0, end = 0.0;  // s: trim started, finished
  int points = 0;                 // stereo points of the bush
  std::optional<perception::TopiaryShape> fit;  // base_link
  double fit_loss = 0.0;                        // m
  int poses = 0, reached = 0;                   // blade poses on the target, and on the path
  bool from_database = false;
  double database_distance = -1.0;      // m to the nearest stored target of the shape (-1: none)
  std::string path_source;              // adapted, or solved in full and why
  double planning_seconds = 0.0;        // wall clock: fit and path
  double motion_time = 0.0;             // s: the path's rest-to-rest moves (the GTSP's cost)
  double nearest_neighbour_time = 0.0;  // s: the greedy tour's, when solved in full
  double cutting_duration = 0.0;        // s: the trajectory executed
  int planned_moves = 0;                // moves planned round the target
  double leaf_depth = 0.0;              // m: the leaves outside the fit, as the scan saw them (leaf_quantile)
  int moves_round_the_leaves = 0;       // of the moves in and out (2 at most): round the leaves, then along the
                                        // blade's axis (the others round the shrunk target only: no such way found)
  int left_out = 0;                     // blade poses at the path's ends left out: no way in or out round the leaves
  int unseen = 0;                       // of the path's blade poses, aimed on the fit: no leaves seen over it there
  int turns_round_the_leaves = 0;       // moves between blade poses out along the axis, round the leaves and in:
                                        // those that turn the blade too far to stay in the swath it cuts or
                                        // tilt it too far off the surface on the way (MaxTurnInLeaves), and
                                        // those a straight move was refused
};

class TrimExecutive {
 public:
  enum class Mode { kIdle, kWaitingForPoints, kFitted, kPlanning, kCutting, kSettling, kDone };

  // `description` must outlive the executive. `database`, when given, is used for every trim.
  TrimExecutive(const robot::RobotDescription& description, const TrimParameters& parameters);
  ~TrimExecutive();
  // Stored cutting paths (trimbot trim precompute). Throws InputError naming the file when it is
  // not one or was made for another arm.
  void SetDatabase(const std::string& path);

  // Trims the bush expected as `expected` (base_link; its exponents are the plan's shape) with
  // `tied` semi-axes; waits for a scan. `bush` names it among the bushes trimmed before (the same
  // bush from another standoff: the fit takes its earlier scans too, placed by the pose estimate
  // `T_map_base` now and at each scan). Without `cut`, done once fitted (a scan for later trims).
  void Start(double stamp, const perception::TopiaryShape& expected, perception::AxesTied tied, int bush,
             const Eigen::Isometry3d& T_map_base, bool cut = true);
  bool WantsPoints() const { return mode_ == Mode::kWaitingForPoints && points_.empty(); }
  // A scan of the surroundings in base_link (all pairs' stereo points).
  void SetPerceivedPoints(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Matrix3d>& covariances);
  // After the fit (kFitted): the base stands where it will cut from; `T_now_scan` is the scan's
  // base_link in the current one.
  void StandsAt(const Eigen::Isometry3d& T_now_scan);
  void SetJointState(const messages::ArmJointState& joints);
  // The arm's command now (none while idle, waiting or done).
  std::optional<messages::ArmCommand> Update(double stamp);

  Mode mode() const { return mode_; }
  bool active() const { return mode_ != Mode::kIdle && mode_ != Mode::kDone; }
  bool cutting() const { return mode_ == Mode::kCutting; }  // the blade spins
  // The mode's name; while cutting, which part of the trajectory runs: "moving in" (to the first
  // blade pose), "cutting" (the path), "moving out" (from the last back to the start).
  std::string Stage(double stamp) const;
  const TrimReport& report() const { return report_; }
  const arm::JointTrajectory& trajectory() const { return trajectory_; }
  // s into trajectory(): the blade at its first pose, and leaving its last.
  double cut_begins() const { return cut_begins_; }
  double cut_ends() const { return cut_ends_; }

 private:
  // The target from the scan; fails the trim with the reason when there is none.
  void Fit(double stamp);
  // The path from the measured joints over the target; the trajectory. Fails the trim with the
  // reason when there is nothing to cut.
  void Plan(double stamp);
  void Finish(double stamp, const std::string& failure);
  // The scan's stereo points within scan_margin of the expected target's surface, above the grass.
  std::vector<Eigen::Vector3d> BushPoints() const;
  // This scan's bush points and, where this scan saw nothing within scan_overlap, the bush's
  // earlier scans (map frame, placed by the pose estimate at each), thinned, in base_link. Where two
  // scans saw the same part, each placed by its own estimate (1-3 cm apart), the fit's quantile
  // - the inner envelope of all points - followed the one placed deepest, and the blade aimed by it
  // cut into the target on the side the robot faces; this scan is the robot's own view of that side.
  std::vector<Eigen::Vector3d> ScansOfTheBush();
  // The joint path through the cutting path's configurations (its free moves as `checks` make them,
  // planned moves round the target), continuous joints unwrapped from the start, and stops_; empty
  // with *failure set when a move cannot be planned.
  std::vector<Eigen::VectorXd> Waypoints(const CuttingPath& path, const CuttingChecks& checks, std::string* failure);
  // From `outside` (clear of the leaves) to `at_blade` (a blade pose): round the leaves as the scan
  // saw them to the blade pose drawn back along the blade's axis, then in along it. Starts at
  // `outside`; ends where `at_blade` puts the blade (continuous joints maybe a turn off); empty
  // when there is no such way.
  std::vector<Eigen::VectorXd> IntoTheLeaves(const Eigen::VectorXd& outside, const Eigen::VectorXd& at_blade);
  // From blade pose `from` to blade pose `to`: drawn back out along the blade's axis, then
  // IntoTheLeaves; empty when there is no such way.
  std::vector<Eigen::VectorXd> RoundTheLeaves(const Eigen::VectorXd& from, const Eigen::VectorXd& to);
  // The blade pose drawn back along its axis past the leaves the scan saw (a Cartesian pass from
  // `at_blade`); empty when the pass is not free.
  std::vector<Eigen::VectorXd> DrawnBack(const Eigen::VectorXd& at_blade);
  // The largest turn of the blade between two poses that keeps the housing in the swath the disc
  // cuts: turning by a about the disc's centre moves the housing's mantle sideways by h sin(a) at
  // height h over the disc, and the leaves stand up to blade_depth + leaf_depth over it; the
  // housing (r_h) stays within the disc (r_b) while that is at most r_b - r_h.
  // The same bounds the blade's tilt off the leaves: they grow along the surface's normal, and one
  // leaning by more than this off the axis passes from beside the swath into the housing.
  double MaxTurnInLeaves() const;
  // The largest angle between the blade's axis and the fitted surface's normal at the blade's
  // centre over the configurations of a free move (CuttingChecks::way): a move between two blade
  // poses, each tangent to the surface, can tilt the blade far off it on the way (the wrist's joints
  // interpolated), though the two poses' axes are close.
  double MaxTilt(const std::vector<Eigen::VectorXd>& way) const;
  // Whether an arm link other than the cutter's reaches into the leaves as the scan saw them (the
  // fitted target grown by leaf_depth): points 1 cm apart on each link's collision cylinder's axis,
  // within the cylinder's radius of that surface along the ray from the target's centre. The
  // cutter's link trails the blade in the swath it cuts (MaxTurnInLeaves); the others - the upper
  // arm reaching over a bush's near edge - would push through leaves no blade has cut.
  bool ArmInLeaves(const Eigen::VectorXd& q) const;
  // Whether the scan saw leaves over the fitted surface along a unit direction from its centre: at
  // least as many of the fit's points (1 / the fit's quantile: enough for one to lie inside it) within
  // the blade's radius of the surface point's normal and scan_margin of the point along it.
  bool LeavesSeenOver(const Eigen::Vector3d& direction) const;
  // The angle between the blade's axes at two arm configurations.
  double BladeTurn(const Eigen::VectorXd& from, const Eigen::VectorXd& to) const;

  TrimParameters parameters_;
  arm::ArmKinematics kinematics_;
  Eigen::Isometry3d T_cutter_blade_;
  double blade_radius_ = 0.0, housing_radius_ = 0.0;  // m: the disc's, the cutter housing's (its link's cylinder)
  double blade_thickness_ = 0.0;                      // m: the disc's
  // The collision cylinders of the arm's links but the cutter's, each with its link's index in
  // kinematics_.links().
  std::vector<std::pair<std::size_t, robot::LinkCylinder>> arm_links_;
  std::unique_ptr<robot::CollisionModel> collision_;
  std::unique_ptr<arm::ArmPlanner> planner_;
  std::optional<CuttingPathDatabase> database_;

  Mode mode_ = Mode::kIdle;
  perception::TopiaryShape expected_;
  perception::AxesTied tied_ = perception::AxesTied::kNone;
  int bush_ = 0;
  bool cut_ = true;
  Eigen::Isometry3d T_map_base_ = Eigen::Isometry3d::Identity();  // estimated, at the scan
  std::map<int, std::vector<Eigen::Vector3d>> scans_;             // each bush's scans, map frame
  perception::TopiaryShape target_shape_;                         // fitted, in the current base_link
  std::vector<Eigen::Vector3d> leaves_;                           // the fit's points, in the current base_link
  double check_depth_ = 0.0;  // m into target_shape_ the collision checks let the blade go (CheckDepth)
  std::vector<Eigen::Vector3d> points_;
  std::vector<Eigen::Matrix3d> covariances_;
  std::optional<messages::ArmJointState> joints_;
  arm::JointTrajectory trajectory_;
  double motion_start_ = 0.0, settle_start_ = 0.0;
  double cut_begins_ = 0.0, cut_ends_ = 0.0;                        // s into trajectory_
  std::size_t first_blade_waypoint_ = 0, last_blade_waypoint_ = 0;  // in Waypoints()' result
  std::vector<bool> stops_;  // per waypoint of Waypoints()' result: the arm stops there (not within a free move)
  Eigen::VectorXd target_;
  TrimReport report_;
};

const char* ToString(TrimExecutive::Mode mode);

}  // namespace trimbot::trimming
