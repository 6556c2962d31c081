#pragma once
// What RobotStack reports after an update, for logs and evaluation: what it believes (pose,
// odometry), what its mission and components are doing, and counters of what they did.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/arm/arm_executive.h"
#include "trimbot/common/pose2.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/perception/local_fusion.h"
#include "trimbot/stack/ekf.h"
#include "trimbot/stack/navigator.h"
#include "trimbot/trimming/trim_executive.h"
#include "trimbot/visual_localization/localizer.h"

namespace trimbot::stack {

// kReaching: the base stands and the arm works through its goals (after the navigation goals).
enum class MissionState { kIdle, kDriving, kReaching, kDone, kFailed };
const char* ToString(MissionState state);

// Wall-clock seconds per component since the start (not deterministic: for the run's timing
// report only).
struct StackTimings {
  double ekf = 0.0;                  // IMU, wheel ticks and fixes into the EKF, wheel odometry
  double visual_localization = 0.0;  // whole frames (split by stage in visual_frames)
  double perception = 0.0;           // stereo clouds and their registration (local fusion)
  double obstacles = 0.0;            // stereo on the pairs ahead, obstacle points, layer, costmap
  long obstacle_pairs = 0;           // stereo pairs those went through
  double bush = 0.0;                 // stereo on the pair facing a bush and the bush's shape fit
  long bush_frames = 0;              // frames that went through
  double planning = 0.0;             // global plans (RRT*)
  std::vector<double> plans;         // each global plan's wall-clock seconds (goal candidates included)
  double arm = 0.0;                  // arm: stereo of its surroundings, planning, execution
  long arm_frames = 0;               // ring frames the arm's surroundings were perceived from
  double control = 0.0;              // navigator and path follower, planning excluded
  // Visual localization: each localized frame's time by stage (features, retrieval, matching, pose).
  std::vector<visual_localization::LocalizationTimings> visual_frames;
};

// A ring frame the stack's visual localization worked on, and what came of it.
struct LocalizationAttempt {
  double stamp = 0.0;                                                                       // the frame's
  visual_localization::FailedStage failed_stage = visual_localization::FailedStage::kNone;  // kNone: a pose
  std::string failure;                                                                      // why not, in words
  int features = 0, matches = 0, inliers = 0;
};

// A pose fix of the stack's own localization as it reached the EKF, with the EKF's verdict.
struct AppliedFix {
  messages::PoseFix fix;
  FixOutcome outcome = FixOutcome::kAccepted;
};

// The stack's own visual localization, counted.
struct VisualLocalizationCounters {
  int attempts = 0;         // ring frames localized
  int fixes = 0;            // of which gave a pose
  int failures = 0;         // no pose (too few features, matches or inliers)
  int stopped_updates = 0;  // control updates the robot stood still for lack of localization
};

// Obstacle detection from stereo, counted.
struct ObstacleCounters {
  int frames = 0;           // pair frames turned into obstacle observations
  int occupied_cells = 0;   // cells of the obstacle layer believed occupied now
  int costmap_updates = 0;  // times the navigator got a new costmap
};

// One frame in which the stack looked for the bush of a bush goal.
struct BushSighting {
  double stamp = 0.0;  // of the frame
  int goal = 0;
  bool found = false;                                     // the shape fit gave a centre
  bool tracked = false;                                   // and the track took it
  Eigen::Vector2d centre_base = Eigen::Vector2d::Zero();  // base_link, at the frame's stamp
  double distance = 0.0;                                  // m, from the arm's axis to the centre
  double bearing = 0.0;  // rad, of the centre seen from the arm's axis (base_link's x: 0)
  double scale = 1.0;    // fitted size / surveyed size
  int points = 0;
  std::string failure;  // when not found
};

// The bush approach under way (servo mode, the track as the arm sees it, the target).
struct BushApproachStatus {
  int goal = -1;
  std::string mode;              // BushServo's mode
  double distance = 0.0;         // m: tracked centre from the arm's axis, now (odometry)
  double bearing = 0.0;          // rad
  double target_distance = 0.0;  // m: the standoff
  double target_bearing = 0.0;   // rad
  int frames = 0, tracked = 0;   // sightings so far for this goal, and taken by the track
};

// The arm's goals under way.
struct ArmStatus {
  std::string mode;            // ArmExecutive's mode
  int goal = 0;                // index into the arm goals
  int perceived_cells = 0;     // occupied cells of the environment the planner avoids
  std::vector<double> target;  // rad: the joint targets commanded now (empty when not moving)
};

// A trim under way (a trim goal's bush, approached).
struct TrimStatus {
  int goal = 0;       // index into the goals
  std::string mode;   // TrimExecutive's mode
  std::string stage;  // and while cutting its part: moving in, cutting, moving out (TrimExecutive::Stage)
};

// A trim finished, for its goal.
struct TrimResult {
  int goal = 0;
  trimming::TrimReport report;
};

// What the stack reports after an update, for logs and evaluation.
struct Telemetry {
  double stamp = 0.0;
  PoseEstimate estimate;  // EKF, map frame
  Pose2 odometry;         // wheel odometry alone, map frame (odom = initial pose)
  MissionState mission = MissionState::kIdle;
  int current_goal = 0;
  std::vector<NavigationEvent> events;                        // of the last update
  EkfCounters localization;                                   // fixes accepted, rejected, re-localizations
  int ring_frames = 0;                                        // received
  int pose_fixes_ignored = 0;                                 // received while no fix source is configured
  std::optional<perception::CloudRegistration> registration;  // local fusion, in the last update
  std::vector<AppliedFix> visual_fixes;              // the stack's own fixes that reached the EKF in the last update
  std::vector<LocalizationAttempt> visual_attempts;  // frames localized since the last update
  VisualLocalizationCounters visual;
  ObstacleCounters obstacles;
  std::vector<BushSighting> bush_sightings;     // looked for in the frames since the last update
  std::optional<BushApproachStatus> bush;       // while a bush goal is the current one
  std::optional<ArmStatus> arm;                 // with arm goals
  std::vector<arm::ArmGoalResult> arm_results;  // arm goals finished in the last update
  std::optional<TrimStatus> trim;               // while a bush is trimmed
  std::vector<TrimResult> trim_results;         // trims finished in the last update
  StackTimings timings;
};

}  // namespace trimbot::stack
