#pragma once
// A navigation scenario: the world (garden, true start, conditions), the robot's prior knowledge
// (the map as surveyed, how well it knows its start, the calibration it reads), its mission
// (goals), the simulated plant's noise and faults, the robot software's settings (`stack:`, over
// robot/config/stack.yaml), how many trials with which seed, and the pass criteria. Read strictly
// from YAML (unknown keys, wrong types, non-finite or out-of-range numbers are errors with file,
// line and key).
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loop/map_recipe.h"
#include "loop/setting.h"
#include "loop/simulated_pose_fixes.h"
#include "trimbot/common/overrides.h"
#include "trimbot/common/yaml_reader.h"
#include "trimbot/garden/garden.h"
#include "trimbot/sim/faults.h"

namespace trimbot::scenarios {

struct PassCriterion {
  std::string metric;      // a batch metric (see ComputeBatchMetrics)
  std::string comparison;  // ">=" (min) or "<=" (max)
  double threshold = 0.0;
};

// How the robot's prior map differs from the garden as it stands in the simulation.
// How well a garden survey made with tapes locates one point (m, per horizontal axis): 20 mm, what
// trilateration from a computed network of control points reaches ("a good point position computed
// using DSM is accurate to 20 mm", 3H Consulting, Site Surveyor: Techniques, 3D trilateration,
// http://www.3hconsulting.com/Techniques3DTrilat.htm). A lower bound for a garden, where a bush's
// centre and outline are picked by eye.
constexpr double kTapeSurveyPointSigma = 0.02;

// Where the robot is put down against where it is believed to be, unless a scenario says
// otherwise (`initial_pose_sigma`): near, not at, a marked start.
constexpr double kInitialPositionSigma = 0.1;            // m per axis
constexpr double kInitialYawSigma = 3.0 * M_PI / 180.0;  // rad

struct Survey {
  // The survey's errors (SurveyedGarden): every object's centre is a point located with
  // `point_sigma` (m, per axis); each extent is the distance between two such points on its
  // outline (sqrt(2) * point_sigma); an elongated object's yaw comes from its two ends (sqrt(2) *
  // point_sigma / length). 0: an exact survey. Seeded by `seed` (default: the scenario's seed; the
  // garden was surveyed once, so every trial of a batch shares the survey).
  double point_sigma = kTapeSurveyPointSigma;
  std::uint64_t seed = 0;
  // A survey drawn afresh for each trial, seeded by the trial's seed, so that a batch measures a
  // rate over surveys rather than one survey's luck (a gap the survey may narrow or widen).
  bool per_trial = false;
  double growth = 0.0;        // foliage as it was when surveyed (0..1, as Conditions)
  std::vector<int> unmapped;  // object ids the survey missed
  // Objects in the world that are not in the garden file either (a wheelbarrow left on the lawn):
  // placed in the simulated world, never in the map. Ids must not be the garden's.
  std::vector<garden::GardenObject> unmapped_objects;
  std::vector<garden::GardenObject> gone;  // objects in the map that are no longer in the garden
};

// Errors of the calibration the stack reads (the simulator renders with the true one). Seeded
// per trial; each a standard deviation.
// A goal of the mission: a point in the map frame, or a bush of the garden to approach for
// trimming (`approach_bush: ID`: by map to ~1 m, then visual servoing to the standoff), or to
// approach and trim from the standoff (`trim_bush: ID`, a topiary; the same bush from several
// standoffs), or to approach and scan only (`scan_bush: ID`: the scan joins the bush's later trims'
// fits). A bush goal's `side_deg` asks for the side of the bush to stand at (the bearing from its
// centre, map frame: 0 east, 90 north); unset, the free side nearest to where the robot comes from.
struct ScenarioGoal {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // a point goal's (a bush's: see MissionGoals)
  std::optional<double> yaw;                           // rad, map frame (`yaw_deg`): a point goal's heading; unset: any
  int bush = 0;                                        // the garden object's id; 0: a point goal
  bool trim = false;                                   // scanned once approached (`scan_bush`) ...
  bool cut = false;                                    // ... and trimmed (`trim_bush`)
  std::optional<double> side;                          // rad, map frame (`side_deg`): a bush goal's side; unset: any
};

// How far a goal's heading may be off when the scenario gives one: Nav2's default
// (SimpleGoalChecker yaw_goal_tolerance, 0.25 rad), what users of a ROS navigation stack expect.
constexpr double kGoalYawTolerance = 0.25;  // rad

// An arm_reach scenario (`arm_reach:`): the base stands at the start; the arm reaches `poses`
// random cutter poses around a bush, each reachable without collision (a witness configuration of
// the joints has this clearance from the garden as the simulator collides with it and the ground,
// and touches neither the arm itself nor the robot), the cutter's tip within the distance band from
// the bush's collision surface and its axis within max_tilt of pointing at the bush's centre.
// Judged on the true cutter pose in base_link against the goal.
struct ArmReach {
  int bush = 0;  // garden object id (a topiary or rose)
  int poses = 10;
  double distance_min = 0.08;             // m
  double distance_max = 0.20;             // m
  double max_tilt = 60.0 * M_PI / 180.0;  // rad
  double min_clearance = 0.08;            // m, of the witness configuration (the stack keeps ~4 cm off what it sees)
  double position_tolerance = 0.01;       // m
  double orientation_tolerance = 2.0 * M_PI / 180.0;  // rad
  int renders = 3;                                    // PNGs of the first poses reached
};

// The real robot's figures for the experiment a scenario mirrors (`robot_reference:`), set beside
// the twin's in the twin-versus-robot report (`trimbot ablate`). Never a pass criterion by itself:
// criteria say what must hold, this says what the robot measured.
struct RobotReference {
  std::string source;  // where the figures come from (document, table)
  // Batch metrics as summary.json names them (IsKnownMetric), in the order given.
  std::vector<std::pair<std::string, double>> metrics;
  double frame_seconds = -1.0;  // typical processing time of a localization frame (s); -1: not given
};

struct Scenario {
  std::string source;  // file it was read from
  std::string name;
  std::string description;
  Setting setting;               // setting.seed is the batch seed; trial i runs with seed + i
  double map_resolution = 0.05;  // m: the robot's prior map, made from the surveyed garden
  // m: the prior map holds each object's part below this height (a tree crown's cross-section
  // there); unset: the robot's top with its arm at home (the URDF) plus 5 cm (MapClearanceHeight).
  std::optional<double> map_clearance_height;
  Survey survey;
  std::vector<ScenarioGoal> goals;  // in order (none in an arm_reach scenario)
  std::optional<ArmReach> arm_reach;
  double goal_tolerance = 0.3;                    // m: a goal counts as reached within this (ground truth)
  double goal_yaw_tolerance = kGoalYawTolerance;  // rad: and within this of its heading, if it has one
  // A bush goal counts as reached when the arm's axis stands within these of the standoff
  // distance and bearing the stack aimed at (ground truth).
  double bush_distance_tolerance = 0.03;                  // m
  double bush_bearing_tolerance = 3.0 * M_PI / 180.0;     // rad
  double initial_position_sigma = kInitialPositionSigma;  // m per axis: the stack's start belief = truth + this noise
  double initial_yaw_sigma = kInitialYawSigma;            // rad
  CalibrationError calibration_error;
  std::string visual_map;  // map file for localization: visual (relative to this file)
  // Stored cutting paths for trim goals (`cutting_path_database:`, relative to this file; made by
  // trimbot trim precompute); empty: each cutting path is solved in full.
  std::string cutting_path_database;
  // Or the mapping drive the map is built from on first use (then cached; the batch sets
  // visual_map to the cached file before any trial runs).
  std::optional<MapRecipe> visual_map_recipe;
  int trials = 1;
  double time_limit = 300.0;        // s of simulated time per trial
  double wall_time_limit = 1800.0;  // s of wall-clock time per trial before it is killed
  bool render_cameras = false;      // the whole ring on the camera schedule (~0.5-0.9 s a frame);
                                    // the stack's own requests are rendered regardless
  double resolution_scale = 0.5;    // of the scheduled ring (a request carries its own)
  bool motion_blur = true;          // images blurred by the rig's motion over their exposure
  double imu_noise_scale = 1.0;
  double wheel_slip_scale = 1.0;
  SimulatedPoseFixParameters simulated_pose_fixes;  // test fixture, used when the stack asks for it
  bool simulated_pose_fixes_given = false;          // the file set them (then the stack must use them)
  std::vector<sim::Fault> faults;
  std::vector<PassCriterion> criteria;
  std::optional<RobotReference> robot_reference;
  std::optional<YamlMap> stack;        // overrides of robot/config/stack.yaml
  std::vector<std::string> overrides;  // --set key=value, as given (recorded with the results)
  std::string effective_yaml;          // the file with the overrides applied (a batch's scenario.yaml)

  // Reads the file with `overrides` applied first, so they are checked like the file's own keys.
  static Scenario Load(const std::string& path, const std::vector<Override>& overrides = {});
};

// Names a criterion may use.
bool IsKnownMetric(const std::string& name);
// A `criteria:` map (metric: {min: v} or {max: v}); InputError naming the file and key when a
// metric is unknown or a bound is not exactly one of min or max.
std::vector<PassCriterion> ReadPassCriteria(const YamlMap& criteria);

}  // namespace trimbot::scenarios
