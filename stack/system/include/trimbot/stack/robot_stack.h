#pragma once
// The robot software as one system: time-stamped sensor messages in, actuator commands out, and a
// telemetry record of what it believes and does. It is built from the robot's files only (URDF,
// camera calibration, robot parameters, stack parameters) and owns its components - wheel
// odometry, the EKF, the navigator with its planner and path follower, local fusion - and their
// scheduling; which components run is configuration (StackParameters), not the caller's wiring.
// Nothing here knows whether the sensors are simulated: the same object could run on the robot.
//
// Use:  RobotStack stack(files, parameters, seed);
//       stack.SetInitialPose(0, believed_start);  stack.SetMap(map_yaml);  stack.SetGoals(goals);
//       (a goal is a point, or Goal::ApproachBush: by map to ~1 m, then visual servoing)
//       per sensor message: stack.Add(message);   then: commands = stack.Update(now);
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/messages/commands.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/perception/bush_estimator.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/stack/stack_parameters.h"
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
  double arm = 0.0;                  // arm: stereo of its surroundings, planning, execution
  long arm_frames = 0;               // ring frames the arm's surroundings were perceived from
  double control = 0.0;              // navigator and path follower, planning excluded
  // Visual localization: each localized frame's time by stage (features, retrieval, matching, pose).
  std::vector<visual_localization::LocalizationTimings> visual_frames;
};

// The stack's own visual localization, counted.
struct VisualLocalizationCounters {
  int attempts = 0;       // ring frames localized
  int fixes = 0;          // of which gave a pose
  int failures = 0;       // no pose (too few features, matches or inliers)
  int stopped_updates = 0;  // control updates the robot stood still for lack of localization
};

// Obstacle detection from stereo, counted.
struct ObstacleCounters {
  int frames = 0;           // pair frames turned into obstacle observations
  int occupied_cells = 0;   // cells of the obstacle layer believed occupied now
  int costmap_updates = 0;  // times the navigator got a new costmap
};

// A goal of the mission: a point to drive to, or a bush to approach for trimming (by map to an
// approach point, then by visual servoing until the arm's axis stands at the standoff).
struct Goal {
  Goal(const Eigen::Vector2d& point) : position(point) {}  // NOLINT(google-explicit-constructor): a point is a goal
  Goal(double x, double y) : position(x, y) {}
  // The bush as the survey knows it: its centre in the map and its shape (yaw in the map frame).
  static Goal ApproachBush(const Eigen::Vector2d& centre, const perception::BushShape& shape);
  Eigen::Vector2d position;                   // the point, or the bush's surveyed centre
  std::optional<perception::BushShape> bush;  // set for a bush approach
};

// One frame in which the stack looked for the bush of a bush goal.
struct BushSighting {
  double stamp = 0.0;      // of the frame
  int goal = 0;
  bool found = false;      // the shape fit gave a centre
  bool tracked = false;    // and the track took it
  Eigen::Vector2d centre_base = Eigen::Vector2d::Zero();  // base_link, at the frame's stamp
  double distance = 0.0;   // m, from the arm's axis to the centre
  double bearing = 0.0;    // rad, of the centre seen from the arm's axis (base_link's x: 0)
  double scale = 1.0;      // fitted size / surveyed size
  int points = 0;
  std::string failure;     // when not found
};

// The bush approach under way (servo mode, the track as the arm sees it, the target).
struct BushApproachStatus {
  int goal = -1;
  std::string mode;               // BushServo's mode
  double distance = 0.0;          // m: tracked centre from the arm's axis, now (odometry)
  double bearing = 0.0;           // rad
  double target_distance = 0.0;   // m: the standoff
  double target_bearing = 0.0;    // rad
  int frames = 0, tracked = 0;    // sightings so far for this goal, and taken by the track
};

// The arm's goals under way.
struct ArmStatus {
  std::string mode;              // ArmExecutive's mode
  int goal = 0;                  // index into the arm goals
  int perceived_cells = 0;       // occupied cells of the environment the planner avoids
  std::vector<double> target;    // rad: the joint targets commanded now (empty when not moving)
};

// What the stack reports after an update, for logs and evaluation.
struct Telemetry {
  double stamp = 0.0;
  PoseEstimate estimate;                 // EKF, map frame
  Pose2 odometry;                        // wheel odometry alone, map frame (odom = initial pose)
  MissionState mission = MissionState::kIdle;
  int current_goal = 0;
  std::vector<NavigationEvent> events;   // of the last update
  EkfCounters localization;              // fixes accepted, rejected, re-localizations
  int ring_frames = 0;                   // received
  int pose_fixes_ignored = 0;            // received while no fix source is configured
  std::optional<perception::CloudRegistration> registration;  // local fusion, in the last update
  std::vector<messages::PoseFix> visual_fixes;  // the stack's own fixes applied in the last update
  VisualLocalizationCounters visual;
  ObstacleCounters obstacles;
  std::vector<BushSighting> bush_sightings;   // looked for in the frames since the last update
  std::optional<BushApproachStatus> bush;     // while a bush goal is the current one
  std::optional<ArmStatus> arm;               // with arm goals
  std::vector<arm::ArmGoalResult> arm_results;  // arm goals finished in the last update
  StackTimings timings;
};

// The stack's visual localizer for `rig` against the map file, configured by `parameters` (one
// place: the stack and the offline localization benchmarks use the same). Throws InputError naming
// the file if it is not a map or was made for another rig or descriptor.
std::unique_ptr<visual_localization::VisualLocalizer> MakeVisualLocalizer(const std::string& map_path,
                                                                         const VisualLocalizationParameters& parameters,
                                                                         const robot::CameraRig& rig);

class RobotStack {
 public:
  // Whether a stack with `parameters` on this mission uses the ring's images (the driver must then
  // deliver what RingRequestAt asks for): its parameters say so, a goal approaches a bush, or the
  // arm has goals (it perceives its surroundings).
  static bool UsesRingImages(const StackParameters& parameters, const std::vector<Goal>& goals, bool arm_goals = false);

  // `seed` seeds the stack's randomized algorithms (the planner's RRT*): same seed, same plans.
  // Throws InputError naming the file and key when a file is missing or malformed.
  RobotStack(const robot::RobotFiles& files, const StackParameters& parameters, std::uint64_t seed);
  ~RobotStack();
  RobotStack(const RobotStack&) = delete;
  RobotStack& operator=(const RobotStack&) = delete;

  // Mission inputs, from the operator.
  // Where the robot was put down, as far as the operator knows (the EKF starts here with the
  // parameters' initial_pose_sigma); the odom frame starts here too.
  void SetInitialPose(double stamp, const Pose2& believed_pose);
  // The prior map of the garden (map_server YAML + PNG); needed before goals.
  void SetMap(const std::string& map_yaml);
  // The visual localization map (trimbot map build); needed with localization: visual. Throws
  // InputError naming the file if it is not a map or was made for another camera rig.
  void SetVisualMap(const std::string& map_path);
  // Goals in the map frame, visited in order; navigation starts with the next update. Needs the
  // prior map, and with localization: visual the visual map (std::logic_error otherwise).
  void SetGoals(const std::vector<Goal>& goals);
  // Cutter poses in base_link for the arm, reached in turn once the navigation goals (if any) are
  // done, while the base stands. The arm plans around what the ring's stereo pairs see then.
  void SetArmGoals(const std::vector<Eigen::Isometry3d>& cutter_poses);
  // Drive by hand: the command passes through to the base (navigation stays idle); the stack
  // still estimates its pose and runs perception.
  void SetTeleopCommand(const messages::BaseVelocityCommand& command);

  // Sensor inputs, in time order per sensor.
  void Add(const messages::ImuSample& imu);
  void Add(const messages::WheelTicks& ticks);
  void Add(const messages::ArmJointState& joints);
  void Add(const messages::RingFrame& frame);
  void Add(const messages::PoseFix& fix);  // used when localization is simulated_pose_fixes

  // What the components would use of a ring frame exposed at `stamp`: the cameras and resolution
  // (empty: nothing; a driver skips the frame or the cameras not named).
  messages::RingRequest RingRequestAt(double stamp) const;

  // Runs the components due at `stamp` (the latest sensor time) and returns the commands.
  messages::RobotCommands Update(double stamp);

  const Telemetry& telemetry() const { return telemetry_; }
  // The navigator's costmap on the prior map's cells (CV_8U, row 0 = the map's top): 0 free,
  // 128 an obstacle of the prior map, 255 an obstacle only perception has seen. Empty before SetMap.
  cv::Mat CostmapLayers() const;
  const StackParameters& parameters() const { return parameters_; }

 private:
  void RunNavigation(double stamp, messages::RobotCommands* commands);
  // The localizer is configured, idle and its rate allows a frame at `stamp`.
  bool VisualLocalizationDue(double stamp) const;
  void LocalizeVisually(const messages::RingFrame& frame);
  void DeliverVisualFixes(double stamp);
  bool LocalizationLost() const;
  // Obstacle detection is configured, has a map, and its rate allows a frame at `stamp`.
  bool ObstacleDetectionDue(double stamp) const;
  // The stereo pairs (indices into the rig's pairs) facing the direction of travel.
  std::vector<int> PairsAhead() const;
  void DetectObstacles(const messages::RingFrame& frame);
  // Mission: gives the navigator the goals from next_goal_ up to the next bush goal (its approach
  // point), from the robot's estimated position.
  void StartSegment();
  Eigen::Vector2d ApproachPoint(const Goal& goal, const Eigen::Vector2d& from) const;
  // The current bush goal's bush in base_link (map belief, or the track once there is one).
  Eigen::Vector2d ExpectedBushInBase() const;
  // The stereo pair facing the current bush goal's bush, if one does and it is in sighting range.
  std::optional<int> PairFacingBush() const;
  bool BushSightingDue(double stamp) const;
  void LookForBush(const messages::RingFrame& frame);
  // Translates the navigator's events for the mission and starts the servo at a bush's approach point.
  void HandleNavigationEvents(double stamp);
  void RunBushServo(double stamp, messages::RobotCommands* commands);
  void FinishBushGoal(double stamp, bool reached, const std::string& detail);
  // The map pose of the servo's frame (GyroOdometry), by the EKF's estimate now.
  Eigen::Isometry3d MapFromServoFrame() const;
  void UpdateMissionTelemetry();
  // No navigation goals, or they are done (the arm's goals come after them).
  bool NavigationGoalsDone() const;
  // The arm waits for its surroundings, the navigation goals are done, and the base stands.
  bool ArmEnvironmentDue() const;
  void PerceiveArmEnvironment(const messages::RingFrame& frame);
  void RunArm(double stamp, messages::RobotCommands* commands);

  StackParameters parameters_;
  struct Components;
  std::unique_ptr<Components> components_;
  Telemetry telemetry_;
  double next_control_ = 0.0;
  std::optional<messages::BaseVelocityCommand> teleop_;
  std::optional<perception::CloudRegistration> pending_registration_;  // reported by the next update
  struct PendingFix {
    double ready = 0.0;
    messages::PoseFix fix;
  };
  std::vector<PendingFix> pending_fixes_;   // visual fixes still "being computed"
  double localizer_busy_until_ = -1.0;
  double next_localization_ = 0.0;
  double next_obstacle_frame_ = 0.0;
  double last_linear_command_ = 0.0;  // m/s: its sign is the direction of travel
  // The mission (SetGoals): goals before next_goal_ are done; bush_goal_ is the bush goal of the
  // current segment (-1: none), servoing_ whether its visual servoing has started.
  std::vector<Goal> mission_;
  int next_goal_ = 0;
  int bush_goal_ = -1;
  bool servoing_ = false;
  bool mission_failed_ = false;
  double next_bush_frame_ = 0.0;
  std::vector<BushSighting> pending_sightings_;  // reported by the next update
  BushApproachStatus bush_status_;
  bool arm_mission_ = false;  // SetArmGoals was given goals
};

}  // namespace trimbot::stack
