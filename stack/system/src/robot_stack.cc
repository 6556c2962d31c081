#include "trimbot/stack/robot_stack.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "arm_environment_component.h"
#include "bush_sighting_component.h"
#include "local_fusion_component.h"
#include "mission.h"
#include "obstacle_detection_component.h"
#include "ring_component.h"
#include "scoped_timer.h"
#include "stack_state.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/stack/global_planner.h"
#include "trimbot/stack/navigator.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/visual_localization/localizer.h"
#include "visual_localization_component.h"

namespace trimbot::stack {

struct RobotStack::Components {
  Components(const robot::RobotFiles& files, const StackParameters& parameters, std::uint64_t seed)
      : state(files, parameters),
        visual(parameters, seed),
        obstacles(parameters, state.rig),
        bush(parameters),
        fusion(parameters.local_fusion, state.rig) {}

  StackState state;
  VisualLocalizationComponent visual;
  ObstacleDetectionComponent obstacles;
  BushSightingComponent bush;
  ArmEnvironmentComponent arm_environment;
  LocalFusionComponent fusion;
  // The ring-frame components in the order they get a frame (Add) and their requests are merged.
  const std::array<RingComponent*, 5> ring{&visual, &obstacles, &bush, &arm_environment, &fusion};
};

std::unique_ptr<visual_localization::VisualLocalizer> MakeVisualLocalizer(const std::string& map_path,
                                                                          const VisualLocalizationParameters& v,
                                                                          const robot::CameraRig& rig) {
  visual_localization::LocalizerOptions options;
  options.features.max_features = v.features;
  options.features.descriptor = v.descriptor;
  options.keyframes = v.keyframes;
  options.prior_radius = v.prior_radius;
  options.pose.min_inliers = v.min_inliers;
  options.pose.min_inlier_ratio = v.min_inlier_ratio;
  if (v.left_cameras_only) {
    for (const auto& pair : rig.StereoPairs()) options.cameras.push_back(pair.left);
    std::sort(options.cameras.begin(), options.cameras.end());
  }
  return std::make_unique<visual_localization::VisualLocalizer>(
      visual_localization::VisualMap::Load(map_path, "", visual_localization::RigSignature(rig), v.descriptor), rig,
      options);
}

// The components keep references to parameters_, which outlives them.
RobotStack::RobotStack(const robot::RobotFiles& files, const StackParameters& parameters, std::uint64_t seed)
    : parameters_(parameters), components_(std::make_unique<Components>(files, parameters_, seed)) {
  SeedPlanner(seed);
  if (components_->obstacles.enabled() && components_->obstacles.PairsAhead(0.0).empty()) {
    throw std::invalid_argument(
        "stack parameters: perception.obstacles.max_bearing_deg leaves no stereo pair "
        "facing forward");
  }
  // The standoff must leave the base's front clear of the bush's surveyed outline.
  const double front = components_->state.outline.max().x() - components_->state.arm_axis.x();
  for (const auto& [key, gap] :
       {std::pair{"bush_approach.servo.surface_gap", parameters_.bush_approach.servo.surface_gap},
        std::pair{"trim.surface_gap", parameters_.trim.surface_gap}}) {
    if (gap < front + parameters_.navigation.stop_clearance) {
      throw std::invalid_argument(std::string("stack parameters: ") + key + " must be at least " +
                                  std::to_string(front + parameters_.navigation.stop_clearance) +
                                  " m (the base's front from the arm's axis, plus navigation.stop_clearance)");
    }
  }
  if (parameters_.trim.surface_gap > parameters_.bush_approach.servo.surface_gap) {
    throw std::invalid_argument(
        "stack parameters: trim.surface_gap must not exceed bush_approach.servo.surface_gap (the base advances "
        "from the approach's standoff to the trim's)");
  }
  next_control_ = 1.0 / parameters_.control_rate_hz;
}

RobotStack::~RobotStack() = default;

bool RobotStack::UsesRingImages(const StackParameters& parameters, const std::vector<Goal>& goals, bool arm_goals) {
  return parameters.UsesRingImages() || HasBushGoal(goals) || arm_goals;
}

void RobotStack::SetInitialPose(double stamp, const Pose2& believed_pose) {
  StackState& state = components_->state;
  const double p = parameters_.initial_position_sigma, yaw = parameters_.initial_yaw_sigma;
  state.ekf.Initialize(stamp, believed_pose, Eigen::Vector3d(p * p, p * p, yaw * yaw).asDiagonal());
  state.odom_origin = believed_pose;
  telemetry_.estimate = state.ekf.Estimate();
  telemetry_.odometry = believed_pose;
}

void RobotStack::SetMap(const std::string& map_yaml) {
  StackState& state = components_->state;
  state.navigator.reset();
  state.map = std::make_unique<OccupancyGrid>(OccupancyGrid::LoadMapServer(map_yaml));
  state.navigator = std::make_unique<Navigator>(*state.map, state.outline, parameters_.navigation);
  components_->obstacles.SetMap(*state.map);
}

cv::Mat RobotStack::CostmapLayers() const {
  const StackState& state = components_->state;
  if (!state.navigator) return {};
  cv::Mat layers = state.navigator->costmap().occupied().clone();  // 255 where occupied
  layers.setTo(128, state.map->occupied());
  return layers;
}

void RobotStack::SetVisualMap(const std::string& map_path) {
  auto localizer = MakeVisualLocalizer(map_path, parameters_.visual, components_->state.rig);
  // The fixes share the map's error: the localizer's covariance floor stands for it (the
  // Gauss-Newton part is each fix's own). A map is one reconstruction, off by its scale and its
  // calibration's biases everywhere at once, so the error decorrelates only over the map's extent
  // (the diagonal of its keyframes' positions), not from one retrieval neighbourhood to the next:
  // with 3 m, the shared state soaked up the wheels' slip and dead reckoning through a 25 s outage
  // ended 9 cm off instead of 4 (rectangle_unmapped, seed 101, which then hit a topiary).
  Eigen::AlignedBox2d extent;
  for (const auto& keyframe : localizer->map().keyframes) extent.extend(keyframe.T_map_base.translation().head<2>());
  const double distance = extent.isEmpty() ? 0.0 : extent.diagonal().norm();
  components_->state.ekf.SetSharedFixError(visual_localization::LocalizerOptions{}.min_position_sigma,
                                           std::max(distance, parameters_.visual.prior_radius));
  components_->visual.SetLocalizer(std::move(localizer));
}

void RobotStack::SetArmGoals(const std::vector<Eigen::Isometry3d>& cutter_poses) {
  StackState& state = components_->state;
  state.mission.SetArmGoals(cutter_poses);
  components_->arm_environment.Prepare(state.mission.has_arm_goals(), state.rig);
}

void RobotStack::SetGoals(const std::vector<Goal>& goals) {
  StackState& state = components_->state;
  if (!state.navigator) throw std::logic_error("RobotStack::SetGoals: no map (call SetMap first)");
  if (parameters_.localization == LocalizationSource::kVisual && !components_->visual.has_localizer()) {
    throw std::logic_error("RobotStack::SetGoals: localization is visual but no visual map was given (SetVisualMap)");
  }
  state.mission.SetGoals(goals);
  components_->bush.Prepare(goals, state.rig);
  components_->arm_environment.Prepare(state.mission.has_arm_goals() || HasTrimGoal(goals), state.rig);
  state.mission.StartSegment(state.navigator.get());
  teleop_.reset();
}

void RobotStack::SetCuttingPathDatabase(const std::string& path) { components_->state.trim.SetDatabase(path); }

void RobotStack::SetTeleopCommand(const messages::BaseVelocityCommand& command) { teleop_ = command; }

void RobotStack::Add(const messages::ImuSample& imu) {
  ScopedTimer timer(&telemetry_.timings.ekf);
  StackState& state = components_->state;
  state.ekf.AddImu(imu);
  if (state.ekf.initialized()) {
    state.servo_odometry.AddYawRate(imu.stamp, imu.angular_velocity.z() - state.ekf.Estimate().gyro_bias);
  }
}

void RobotStack::Add(const messages::WheelTicks& ticks) {
  ScopedTimer timer(&telemetry_.timings.ekf);
  StackState& state = components_->state;
  state.ekf.AddWheelTicks(ticks);
  state.odometry.Update(ticks);
  state.servo_odometry.AddWheelTicks(ticks);
}

void RobotStack::Add(const messages::ArmJointState& joints) {
  components_->state.arm.SetJointState(joints);
  components_->state.trim.SetJointState(joints);
}

void RobotStack::Add(const messages::RingFrame& frame) {
  ++telemetry_.ring_frames;
  // Each component is asked just before its turn: those before it may have changed what it reads.
  for (RingComponent* component : components_->ring) {
    if (component->Due(frame.stamp, components_->state)) component->Consume(frame, &components_->state, &telemetry_);
  }
}

void RobotStack::Add(const messages::PoseFix& fix) {
  if (parameters_.localization != LocalizationSource::kSimulatedPoseFixes) {
    ++telemetry_.pose_fixes_ignored;
    return;
  }
  ScopedTimer timer(&telemetry_.timings.ekf);
  components_->state.ekf.AddPoseFix(fix);
}

messages::RingRequest RobotStack::RingRequestAt(double stamp) const {
  messages::RingRequest request;
  for (const RingComponent* component : components_->ring) {
    request = messages::Merge(request, component->Wants(stamp, components_->state));
  }
  return request;
}

messages::RobotCommands RobotStack::Update(double stamp) {
  StackState& state = components_->state;
  messages::RobotCommands commands;
  telemetry_.events.clear();
  telemetry_.registration = components_->fusion.TakeRegistration();
  telemetry_.bush_sightings = components_->bush.TakeSightings();
  telemetry_.visual_attempts = components_->visual.TakeAttempts();
  telemetry_.arm_results.clear();
  telemetry_.trim_results.clear();
  components_->visual.DeliverFixes(stamp, &state.ekf, &telemetry_);
  if (stamp + 1e-9 >= next_control_) {
    // Control ticks at whole multiples of the period (no drift from summing periods).
    next_control_ = (std::floor((stamp + 1e-9) * parameters_.control_rate_hz) + 1.0) / parameters_.control_rate_hz;
    RunNavigation(stamp, &commands);
    if (state.mission.has_arm_goals()) state.mission.RunArm(stamp, &commands, &telemetry_);
  }
  telemetry_.stamp = stamp;
  telemetry_.estimate = state.ekf.Estimate();
  telemetry_.odometry = ToPose2(ToIsometry(state.odom_origin) * ToIsometry(state.odometry.pose()));
  telemetry_.localization = state.ekf.counters();
  return commands;
}

void RobotStack::RunNavigation(double stamp, messages::RobotCommands* commands) {
  StackState& state = components_->state;
  if (teleop_) {
    commands->base = *teleop_;
    state.last_linear_command = teleop_->linear;
    return;
  }
  Navigator* navigator = state.navigator.get();
  if (navigator == nullptr) return;
  const double planning_before = navigator->planning_seconds();
  const auto start = std::chrono::steady_clock::now();
  if (state.mission.trimming()) {
    state.mission.RunTrim(stamp, navigator, commands, &telemetry_);
  } else if (state.mission.servoing()) {
    // On odometry and stereo alone: the servo needs no map pose.
    state.mission.RunBushServo(stamp, navigator, commands, &telemetry_);
  } else if (components_->visual.Lost(state.ekf)) {
    // Better to stand than to drive blind: wait for the localization to come back.
    commands->base = messages::BaseVelocityCommand{};
    ++telemetry_.visual.stopped_updates;
  } else {
    commands->base = navigator->Update(stamp, state.ekf.Estimate().pose);
    telemetry_.events = navigator->TakeEvents();
    state.mission.HandleNavigationEvents(stamp, &telemetry_);
  }
  state.last_linear_command = commands->base ? commands->base->linear : 0.0;
  state.mission.UpdateTelemetry(*navigator, &telemetry_);
  const double planning = navigator->planning_seconds() - planning_before;
  telemetry_.timings.planning += planning;
  if (planning > 0.0) telemetry_.timings.plans.push_back(planning);  // a navigator update makes at most one plan
  const double control = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - planning;
  telemetry_.timings.control += control;
}

}  // namespace trimbot::stack
