#pragma once
// Plain data between the stages of a batch: each trial ends in a TrialResult (written as
// trials/NNN/result.json by the process that ran it); a batch (one run, or shards merged) turns
// the trial results into a BatchSummary with the scenario's pass criteria evaluated.
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace trimbot::scenarios {

// Statistics of a set of error samples (all zero with count 0 when there are none).
struct ErrorStats {
  int count = 0;
  double mean = 0.0, median = 0.0, rmse = 0.0, max = 0.0;
  static ErrorStats From(std::vector<double> samples);
};

// Error of one pose estimate (ekf, wheel_odometry, pose_fixes) against ground truth, sampled at
// the estimate's own stamps (fixes) or at the evaluation rate (filters).
// The 95 % quantile of the chi-square distribution with 3 degrees of freedom.
constexpr double kChiSquare3Dof95 = 7.8147;
// The share of these (3-dof) NEES values within the 95 % bound: 0.95 when consistent (0 for none).
double NeesWithin95Rate(const std::vector<double>& nees);

struct EstimateErrors {
  std::string name;
  std::vector<double> position_m;   // samples, metres
  std::vector<double> heading_deg;  // samples, degrees (absolute)
  // Normalized estimation error squared of (x, y, yaw) under the estimate's own covariance, per
  // sample (the EKF only): a consistent filter's is chi-square with 3 dof (mean 3, 95 % of samples
  // below 7.81).
  std::vector<double> nees;
  ErrorStats position() const { return ErrorStats::From(position_m); }
  ErrorStats heading() const { return ErrorStats::From(heading_deg); }
};

struct GoalResult {
  double x = 0.0, y = 0.0;      // goal in the map frame
  bool reached = false;         // the robot declared arrival and was within tolerance (ground truth)
  double arrival_time = -1.0;   // s of simulated time since the trial's start, -1 if never
  double final_error_m = -1.0;  // ground-truth distance to the goal when the robot declared arrival
  // A goal inside an obstacle's clearance is moved by the robot to the nearest point it can arrive
  // at (within its goal_search_radius): arrival is judged there, and the move is reported.
  double adjusted_by_m = 0.0;         // 0: the goal as asked
  double used_x = 0.0, used_y = 0.0;  // the goal navigated to (as asked, or adjusted)
  bool reached_as_asked = false;      // reached, and within the tolerance of the goal as asked
  // A goal with a heading: the true heading's difference to it at the declared arrival (reached:
  // also within the scenario's goal_yaw_tolerance).
  std::optional<double> yaw_deg;                  // the goal's heading
  std::optional<double> final_heading_error_deg;  // true heading - the goal's, at arrival
  // A bush goal (approach_bush): the arm's axis at the robot's true pose against the bush's true
  // centre when the robot declared arrival (reached: both errors within the bush tolerance).
  int bush = 0;                                  // garden object id; 0: a point goal
  double bush_distance_error_m = 0.0;            // true distance - the standoff the stack aimed at
  double bush_bearing_error_deg = 0.0;           // true bearing - the bearing it aimed at
  double bush_estimate_distance_error_m = 0.0;   // the stack's tracked distance - the true one
  double bush_estimate_bearing_error_deg = 0.0;  // the stack's tracked bearing - the true one
};

// One frame in which the stack looked for a bush: its estimate against the truth at the frame.
struct BushFrame {
  double t = 0.0;
  int goal = 0;
  double true_distance_m = 0.0;  // arm's axis to the bush's true centre
  double true_bearing_deg = 0.0;
  bool found = false;             // the stack's fit gave a centre (errors below are then set)
  double distance_error_m = 0.0;  // estimated - true
  double bearing_error_deg = 0.0;
};

// One goal of an arm_reach trial: what the stack reported and the truth (cutter pose in base_link
// from the simulator, MuJoCo's contacts, the arm's clearance from the garden as it collides).
struct ArmGoalOutcome {
  int goal = 0;
  double x = 0.0, y = 0.0, z = 0.0;  // the goal's cutter position, base_link
  bool reached = false;              // the stack reported it reached, the true errors within tolerance, no contact
  bool stack_reached = false;        // the stack reported it reached
  std::string failure;               // the stack's reason when it did not
  double position_error_m = -1.0;    // true cutter - goal when the stack finished the goal
  double orientation_error_deg = -1.0;
  double witness_clearance_m = 0.0;  // of the generator's joint configuration for the pose
  int ik_solutions = 0;
  int free_goals = 0;  // collision-free solutions, as the stack perceived its surroundings
  double path_length_rad = 0.0;
  double cutter_path_length_m = 0.0;
  double motion_seconds = 0.0;
  double tracking_error_max_rad = 0.0;  // true joints against the commanded targets, over the motion
  double min_clearance_m = -1.0;        // true, while working on this goal (-1: not sampled)
  int contacts = 0;                     // arm contact events while working on this goal
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(ArmGoalOutcome, goal, x, y, z, reached, stack_reached, failure, position_error_m,
                                   orientation_error_deg, witness_clearance_m, ik_solutions, free_goals,
                                   path_length_rad, cutter_path_length_m, motion_seconds, tracking_error_max_rad,
                                   min_clearance_m, contacts)

// One trim goal's bush (`trim_bush`): its foliage against the target shape before and after
// (ground truth, van Marrewijk et al.'s measure: the share of the surface within 2 cm), what the
// stack reported of its trim, its fit against the true target, and what the arm touched meanwhile.
struct TrimOutcome {
  int goal = 0;
  int bush = 0;                    // garden object id
  bool success = false;            // cut, no arm contact, no link but the blade in the foliage
  bool cut = false;                // the stack executed its cutting path to the end
  std::string failure;             // the stack's reason when it did not
  double within_2cm_before = 0.0;  // share of the foliage surface within 2 cm of the target
  double within_2cm_after = 0.0;
  double within_2cm_upper_before = 0.0;  // the same above the target's centre (the half the arm reaches)
  double within_2cm_upper_after = 0.0;
  double overcut_share = 0.0;  // of the target's volume cut away
  // The bush as this trim left it (the fields above: as the trial left it, after every trim of it),
  // so each side's part can be told apart.
  double within_2cm_at_trim_end = 0.0;
  double overcut_share_at_trim_end = 0.0;
  double overgrowth_before_m3 = 0.0;  // foliage volume outside the target
  double overgrowth_after_m3 = 0.0;
  double cutting_seconds = 0.0;             // simulated, the blade spinning
  double trim_seconds = 0.0;                // simulated, from the approach's end to the arm back at rest
  int points = 0;                           // stereo points of the bush the fit used
  int poses = 0, reached_poses = 0;         // blade poses on the fitted target, and on the path
  bool from_database = false;               // the path adapted from a stored one
  std::string path_source;                  // the stack's words: adapted, or solved in full and why
  double motion_seconds = 0.0;              // the path's move times (the GTSP's cost)
  double nearest_neighbour_seconds = 0.0;   // the greedy tour's (solved in full only)
  double fit_centre_error_m = -1.0;         // the fitted centre from the true one (-1: no fit)
  double fit_axes_error_max_m = -1.0;       // the largest semi-axis error
  std::vector<double> fit_centre_offset_m;  // fitted - true centre, map frame (x, y, z; empty: no fit)
  std::vector<double> fit_half_m;           // the fitted semi-axes
  double leaf_depth_m = 0.0;                // the leaves outside the fit as the stack saw them
  int moves_round_the_leaves = 0;           // of the arm's moves in and out (2), round the seen leaves
  int poses_left_out = 0;                   // blade poses at the path's ends with no way in or out round them
  int poses_unseen = 0;                     // of the path's, aimed on the fit: the scan saw no leaves over it there
  int turns_round_the_leaves = 0;           // moves between blade poses out, round the seen leaves and in
  int arm_contacts = 0;                     // contact events of the arm (MuJoCo: the wood, the ground, itself)
  int foliage_touches = 0;                  // events of an arm link other than the blade reaching into the foliage
  std::map<std::string, int> foliage_touches_by;  // the same by "<link> while <the trim's stage>"
  std::map<std::string, int> arm_contacts_by;     // arm_contacts by "<arm geom> with <geom> while <stage>"
};
// Fields missing from a result written before they were added read as their defaults (a suite
// resumed over older batches).
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(
    TrimOutcome, goal, bush, success, cut, failure, within_2cm_before, within_2cm_after, within_2cm_upper_before,
    within_2cm_upper_after, overcut_share, within_2cm_at_trim_end, overcut_share_at_trim_end, overgrowth_before_m3,
    overgrowth_after_m3, cutting_seconds, trim_seconds, points, poses, reached_poses, from_database, path_source,
    motion_seconds, nearest_neighbour_seconds, fit_centre_error_m, fit_axes_error_max_m, fit_centre_offset_m,
    fit_half_m, leaf_depth_m, moves_round_the_leaves, poses_left_out, poses_unseen, turns_round_the_leaves,
    arm_contacts, foliage_touches, foliage_touches_by, arm_contacts_by)

// A trim's wall-clock time beside its simulated time (issue 31: trimming one bush must not take
// longer in wall time than in simulated time). Wall clock: timing.json only, never summary.json.
struct TrimTiming {
  int goal = 0;
  int bush = 0;
  double simulated_seconds = 0.0;  // from the approach's end to the arm back at rest (TrimOutcome::trim_seconds)
  double wall_seconds = 0.0;       // the same span, wall clock: the stack's planning, the ring's rendering, ...
  double planning_seconds = 0.0;   // of it, the stack's fit and path (wall clock)
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(TrimTiming, goal, bush, simulated_seconds, wall_seconds, planning_seconds)

struct TrialResult {
  int index = 0;
  std::uint64_t seed = 0;
  std::string status = "not run";  // completed | failed | timeout | crashed | error
  std::string message;             // why a trial did not complete
  bool success = false;            // every goal reached, no collision
  std::vector<GoalResult> goals;
  double simulated_seconds = 0.0;
  double wall_seconds = 0.0;   // not in result.json / summary.json (see timing.json): not reproducible
  double path_length_m = 0.0;  // ground truth
  int collisions = 0;          // separate contact events with garden objects
  double contact_seconds = 0.0;
  // Smallest distance between the base's outline (URDF collision geometry of the base and wheels)
  // at its true pose and the garden as it is (m, negative: overlap); absent when not measured.
  std::optional<double> min_clearance_m;
  int replans = 0;
  int recoveries = 0;  // obstacle stops followed by a recovery manoeuvre
  int fixes_accepted = 0, fixes_rejected = 0, relocalizations = 0;
  // Share of the 10 Hz evaluation samples, from the first pose fix on, with a fix stamped within
  // 0.5 s (Table 2's last column of D3.4); -1 when no fix arrived.
  double localization_rate = -1.0;
  // Ring frames the stack's visual localizer tried (0: it did not run). With fixes_accepted, the
  // per-frame success the localization rate hides: at 2 Hz one fix covers a whole second.
  int visual_frames_attempted = 0;
  // Those frames by what came of them (LocalizationLog::Outcomes), and the control updates the
  // robot stood still because its position was too uncertain to drive on.
  std::map<std::string, int> visual_frame_outcomes;
  int localization_stopped_updates = 0;
  std::vector<std::string> faults;  // what was injected, in words
  std::vector<EstimateErrors> estimates;
  std::vector<BushFrame> bush_frames;        // bush goals' sightings
  std::vector<ArmGoalOutcome> arm_goals;     // arm_reach trials
  int arm_contacts = 0;                      // arm contact events (MuJoCo), all goals
  std::vector<double> arm_planning_seconds;  // wall clock per plan: timing.json only, not reproducible
  std::vector<TrimOutcome> trims;            // trim goals
  std::vector<TrimTiming> trim_timings;      // wall clock per trim: timing.json only, not reproducible
};

// One pass criterion of the scenario, e.g. success_rate >= 1.0.
struct CriterionResult {
  std::string name;        // metric name as in the scenario file
  std::string comparison;  // ">=" or "<="
  double expected = 0.0;
  double actual = 0.0;
  bool pass = false;
};

struct BatchSummary {
  std::string scenario;  // scenario name
  std::string scenario_file;
  std::vector<std::string> overrides;  // --set key=value the batch ran with
  std::uint64_t seed = 0;              // batch seed; trial seeds are in the trials
  int trials_planned = 0;
  std::vector<TrialResult> trials;
  // Aggregates over all trials (samples pooled over trials).
  nlohmann::json metrics;  // name -> number; see ComputeBatchMetrics
  std::vector<CriterionResult> criteria;
  bool pass = false;
};

void to_json(nlohmann::json& j, const ErrorStats& s);
void to_json(nlohmann::json& j, const EstimateErrors& e);
void from_json(const nlohmann::json& j, EstimateErrors& e);
void to_json(nlohmann::json& j, const GoalResult& g);
void from_json(const nlohmann::json& j, GoalResult& g);
void to_json(nlohmann::json& j, const BushFrame& f);
void from_json(const nlohmann::json& j, BushFrame& f);
void to_json(nlohmann::json& j, const TrialResult& t);
void from_json(const nlohmann::json& j, TrialResult& t);
void to_json(nlohmann::json& j, const CriterionResult& c);
void to_json(nlohmann::json& j, const BatchSummary& b);

// Batch metrics from the trials: success_rate (trials with success / trials planned; a trial that
// never ran counts as failed), goal_success_rate, trials_completed, collisions, recoveries,
// mean_trial_seconds (simulated), mean_path_length_m, localization_rate (mean over trials with fixes), with the
// stack's visual localization visual_frame_success_rate (fixes the EKF accepted / frames attempted, pooled) and
// visual_frame_rate_hz (frames attempted per simulated second), and per estimate
// E (ekf, wheel_odometry, pose_fixes): E_position_error_{mean,median,max,rmse}_m and
// E_heading_error_{mean,median,max}_deg over the pooled samples (absent when E has no samples), and for the
// EKF and the pose fixes their consistency against their stated covariances: E_nees_mean (3 when
// consistent) and E_nees_within_95_rate (0.95 when consistent);
// with bush goals: bush_goals, bush_{distance,bearing}_error_{mean,max} (final pose, absolute,
// m / deg), bush_estimate_{distance,bearing}_error_{mean,max} (the stack's final estimate), and
// over the frames at 1-3 m: bush_frames_1_3m, bush_frame_found_rate, bush_frame_{distance,
// bearing}_error_{mean,max}, bush_frame_within_rate (within 5 cm and 3 deg); with arm goals:
// arm_goals, arm_success_rate, arm_contacts, arm_position_error_{mean,max}_m,
// arm_orientation_error_{mean,max}_deg (goals the stack reported reached), arm_tracking_error_max_rad,
// arm_min_clearance_m, arm_path_length_mean_rad, arm_cutter_path_length_mean_m; with trim goals:
// trim_goals, trim_success_rate, trim_arm_contacts, trim_foliage_touches,
// trim_within_2cm_{before_mean,after_mean,after_min}, trim_within_2cm_upper_{before_mean,after_mean},
// trim_overcut_{mean,max},
// trim_fit_centre_error_max_m, trim_cutting_seconds_mean.
nlohmann::json ComputeBatchMetrics(const std::vector<TrialResult>& trials, int trials_planned);

}  // namespace trimbot::scenarios
