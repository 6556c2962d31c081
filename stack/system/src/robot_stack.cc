#include "trimbot/stack/robot_stack.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "trimbot/common/input_error.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/robot/robot_parameters.h"
#include "trimbot/stack/ekf.h"
#include "trimbot/stack/global_planner.h"
#include "trimbot/stack/navigator.h"
#include "trimbot/stack/obstacle_layer.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/perception/obstacle_points.h"
#include "trimbot/perception/stereo.h"
#include "trimbot/stack/wheel_odometry.h"
#include "trimbot/common/random.h"
#include "trimbot/visual_localization/localizer.h"

namespace trimbot::stack {
namespace {

using Clock = std::chrono::steady_clock;

// Adds the wall-clock time of a scope to a timing counter.
class ScopedTimer {
 public:
  explicit ScopedTimer(double* total) : total_(total), start_(Clock::now()) {}
  ~ScopedTimer() { *total_ += std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  double* total_;
  Clock::time_point start_;
};

MissionState ToMission(Navigator::Mode mode) {
  switch (mode) {
    case Navigator::Mode::kIdle: return MissionState::kIdle;
    case Navigator::Mode::kFollowing:
    case Navigator::Mode::kBackingOff: return MissionState::kDriving;
    case Navigator::Mode::kDone: return MissionState::kDone;
    case Navigator::Mode::kFailed: return MissionState::kFailed;
  }
  return MissionState::kIdle;
}

}  // namespace

const char* ToString(MissionState state) {
  switch (state) {
    case MissionState::kIdle: return "idle";
    case MissionState::kDriving: return "driving";
    case MissionState::kDone: return "done";
    case MissionState::kFailed: return "failed";
  }
  return "?";
}

struct RobotStack::Components {
  robot::RobotDescription description;
  robot::CameraRig rig;
  int ticks_per_revolution = 0;
  WheelOdometry odometry;
  Ekf ekf;
  Pose2 odom_origin;                              // map pose of the odom frame
  std::unique_ptr<OccupancyGrid> map;
  std::unique_ptr<Navigator> navigator;
  std::unique_ptr<perception::LocalFusion> fusion;
  std::unique_ptr<perception::RingStereo> obstacle_stereo;  // with obstacle detection on
  std::unique_ptr<ObstacleLayer> obstacle_layer;            // made with the map
  std::unique_ptr<visual_localization::VisualLocalizer> localizer;
  Rng latency_rng;

  Components(const robot::RobotFiles& files, const StackParameters& parameters)
      : description(robot::RobotDescription::Load(files.urdf)),
        rig(robot::CameraRig::LoadKalibr(files.camchain,
                                         description.FramePose(robot::RobotFrames::CameraOptical(0)))),
        ticks_per_revolution(robot::RobotParameters::Load(files.robot_parameters).wheel_encoders.ticks_per_revolution),
        odometry(description.drive(), ticks_per_revolution),
        ekf(parameters.ekf, description.drive(), ticks_per_revolution),
        latency_rng(0) {
    if (parameters.local_fusion.enabled) fusion = std::make_unique<perception::LocalFusion>(rig, parameters.local_fusion);
    if (parameters.obstacles.enabled) {
      perception::StereoOptions stereo;
      stereo.stride = parameters.obstacles.stride;
      obstacle_stereo = std::make_unique<perception::RingStereo>(rig, stereo);
    }
  }
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
  if (v.left_cameras_only) {
    for (const auto& pair : rig.StereoPairs()) options.cameras.push_back(pair.left);
    std::sort(options.cameras.begin(), options.cameras.end());
  }
  return std::make_unique<visual_localization::VisualLocalizer>(
      visual_localization::VisualMap::Load(map_path, "", visual_localization::RigSignature(rig), v.descriptor), rig,
      options);
}

RobotStack::RobotStack(const robot::RobotFiles& files, const StackParameters& parameters, std::uint64_t seed)
    : parameters_(parameters), components_(std::make_unique<Components>(files, parameters)) {
  SeedPlanner(seed);
  if (components_->obstacle_stereo && PairsAhead().empty()) {
    throw std::invalid_argument("stack parameters: perception.obstacles.max_bearing_deg leaves no stereo pair "
                                "facing forward");
  }
  components_->latency_rng = MakeRng(seed, "visual_localization_latency");
  next_control_ = 1.0 / parameters_.control_rate_hz;
}

RobotStack::~RobotStack() = default;

void RobotStack::SetInitialPose(double stamp, const Pose2& believed_pose) {
  const double p = parameters_.initial_position_sigma, yaw = parameters_.initial_yaw_sigma;
  components_->ekf.Initialize(stamp, believed_pose, Eigen::Vector3d(p * p, p * p, yaw * yaw).asDiagonal());
  components_->odom_origin = believed_pose;
  telemetry_.estimate = components_->ekf.Estimate();
  telemetry_.odometry = believed_pose;
}

void RobotStack::SetMap(const std::string& map_yaml) {
  components_->navigator.reset();
  components_->map = std::make_unique<OccupancyGrid>(OccupancyGrid::LoadMapServer(map_yaml));
  components_->navigator = std::make_unique<Navigator>(*components_->map, parameters_.navigation);
  if (components_->obstacle_stereo) {
    components_->obstacle_layer = std::make_unique<ObstacleLayer>(*components_->map, parameters_.obstacles.layer);
  }
}

cv::Mat RobotStack::CostmapLayers() const {
  if (!components_->navigator) return {};
  cv::Mat layers = components_->navigator->costmap().occupied().clone();  // 255 where occupied
  layers.setTo(128, components_->map->occupied());
  return layers;
}

void RobotStack::SetVisualMap(const std::string& map_path) {
  components_->localizer = MakeVisualLocalizer(map_path, parameters_.visual, components_->rig);
}

void RobotStack::SetGoals(const std::vector<Eigen::Vector2d>& goals) {
  if (!components_->navigator) throw std::logic_error("RobotStack::SetGoals: no map (call SetMap first)");
  if (parameters_.localization == LocalizationSource::kVisual && !components_->localizer) {
    throw std::logic_error("RobotStack::SetGoals: localization is visual but no visual map was given (SetVisualMap)");
  }
  components_->navigator->SetGoals(goals);
  teleop_.reset();
}

void RobotStack::SetTeleopCommand(const messages::BaseVelocityCommand& command) { teleop_ = command; }

void RobotStack::Add(const messages::ImuSample& imu) {
  ScopedTimer timer(&telemetry_.timings.ekf);
  components_->ekf.AddImu(imu);
}

void RobotStack::Add(const messages::WheelTicks& ticks) {
  ScopedTimer timer(&telemetry_.timings.ekf);
  components_->ekf.AddWheelTicks(ticks);
  components_->odometry.Update(ticks);
}

void RobotStack::Add(const messages::ArmJointState& /*joints*/) {
  // No arm software yet (the arm stack will track its joints here).
}

void RobotStack::Add(const messages::RingFrame& frame) {
  ++telemetry_.ring_frames;
  if (VisualLocalizationDue(frame.stamp)) LocalizeVisually(frame);
  if (ObstacleDetectionDue(frame.stamp)) DetectObstacles(frame);
  if (components_->fusion && components_->fusion->Wants(frame.stamp)) {
    ScopedTimer timer(&telemetry_.timings.perception);
    // The odometry pose at the frame's stamp: wheel ticks up to the frame have been added.
    pending_registration_ = components_->fusion->Add(frame, ToIsometry(components_->odometry.pose()));
  }
}

void RobotStack::Add(const messages::PoseFix& fix) {
  if (parameters_.localization != LocalizationSource::kSimulatedPoseFixes) {
    ++telemetry_.pose_fixes_ignored;
    return;
  }
  ScopedTimer timer(&telemetry_.timings.ekf);
  components_->ekf.AddPoseFix(fix);
}

bool RobotStack::VisualLocalizationDue(double stamp) const {
  return parameters_.localization == LocalizationSource::kVisual && components_->localizer &&
         stamp + 1e-9 >= next_localization_ && stamp >= localizer_busy_until_;
}

messages::RingRequest RobotStack::RingRequestAt(double stamp) const {
  messages::RingRequest request;
  if (VisualLocalizationDue(stamp)) {
    request.cameras = components_->localizer->cameras();
    request.resolution_scale = parameters_.visual.image_scale;
  }
  if (ObstacleDetectionDue(stamp)) {
    messages::RingRequest ahead;
    for (int pair : PairsAhead()) {
      const robot::StereoPair& cameras =
          components_->obstacle_stereo->rectifiers()[static_cast<std::size_t>(pair)].pair();
      ahead.cameras.push_back(cameras.left);
      ahead.cameras.push_back(cameras.right);
    }
    std::sort(ahead.cameras.begin(), ahead.cameras.end());
    ahead.resolution_scale = 1.0;  // stereo rectifies with the calibration's image size
    request = messages::Merge(request, ahead);
  }
  if (components_->fusion != nullptr && components_->fusion->Wants(stamp)) {
    messages::RingRequest stereo;
    for (int i = 0; i < components_->rig.size(); ++i) stereo.cameras.push_back(i);
    stereo.resolution_scale = 1.0;  // stereo rectifies with the calibration's image size
    request = messages::Merge(request, stereo);
  }
  return request;
}

bool RobotStack::ObstacleDetectionDue(double stamp) const {
  return components_->obstacle_stereo && components_->obstacle_layer && stamp + 1e-9 >= next_obstacle_frame_;
}

std::vector<int> RobotStack::PairsAhead() const {
  // Backing off looks backwards; driving, turning or standing looks forwards.
  const double travel = last_linear_command_ < 0.0 ? M_PI : 0.0;
  std::vector<int> pairs;
  const auto& rectifiers = components_->obstacle_stereo->rectifiers();
  for (std::size_t i = 0; i < rectifiers.size(); ++i) {
    const Eigen::Vector3d axis = rectifiers[i].T_base_rectified_left().linear().col(2);
    const double bearing = std::atan2(axis.y(), axis.x());
    if (std::abs(std::remainder(bearing - travel, 2.0 * M_PI)) <= parameters_.obstacles.max_bearing) {
      pairs.push_back(static_cast<int>(i));
    }
  }
  return pairs;
}

void RobotStack::DetectObstacles(const messages::RingFrame& frame) {
  ScopedTimer timer(&telemetry_.timings.obstacles);
  Components& c = *components_;
  next_obstacle_frame_ = frame.stamp + 1.0 / parameters_.obstacles.rate_hz;
  const auto has = [&](int camera) {
    return std::any_of(frame.images.begin(), frame.images.end(),
                       [camera](const messages::Image& image) { return image.camera_index == camera; });
  };
  const Eigen::Isometry3d T_map_base = ToIsometry(c.ekf.Estimate().pose);
  perception::ObstaclePointOptions options = parameters_.obstacles.points;
  // The robot's own body (base, ring, arm at rest) is the footprint's box with a margin.
  const Footprint& footprint = parameters_.navigation.planner.footprint;
  const auto [lowest, highest] = std::minmax_element(footprint.circle_x.begin(), footprint.circle_x.end());
  const double margin = 0.05;
  options.robot_min = {*lowest - footprint.circle_radius - margin, -footprint.circle_radius - margin};
  options.robot_max = {*highest + footprint.circle_radius + margin, footprint.circle_radius + margin};
  ObstacleObservation observation;
  observation.stamp = frame.stamp;
  observation.min_obstacle_height = options.min_height;
  for (int pair : PairsAhead()) {
    const perception::StereoRectifier& rectifier = c.obstacle_stereo->rectifiers()[static_cast<std::size_t>(pair)];
    if (!has(rectifier.pair().left) || !has(rectifier.pair().right)) continue;  // not delivered
    const perception::RingStereo::PairResult result = c.obstacle_stereo->ComputePair(frame, pair);
    const perception::ObstaclePoints points =
        perception::FindObstaclePoints(result.cloud, rectifier.T_base_rectified_left().translation(), options);
    ObstacleView view;
    view.sensor = (T_map_base * points.sensor).head<2>();
    view.sensor_height = points.ground.Distance(points.sensor);
    view.obstacles.reserve(points.obstacles.size());
    for (const Eigen::Vector3d& p : points.obstacles) view.obstacles.push_back((T_map_base * p).head<2>());
    view.ground.reserve(points.ground_points.size());
    for (const Eigen::Vector3d& p : points.ground_points) view.ground.push_back((T_map_base * p).head<2>());
    observation.views.push_back(std::move(view));
    ++telemetry_.timings.obstacle_pairs;
  }
  if (observation.views.empty()) return;
  c.obstacle_layer->Integrate(observation);
  ++telemetry_.obstacles.frames;
  telemetry_.obstacles.occupied_cells = c.obstacle_layer->OccupiedCells();
  if (c.navigator) {
    c.navigator->SetCostmap(c.obstacle_layer->MergedWith(*c.map));
    ++telemetry_.obstacles.costmap_updates;
  }
}

void RobotStack::LocalizeVisually(const messages::RingFrame& frame) {
  ScopedTimer timer(&telemetry_.timings.visual_localization);
  Components& c = *components_;
  std::optional<Eigen::Vector2d> prior;
  if (c.ekf.initialized()) {
    const Pose2 estimate = c.ekf.Estimate().pose;
    prior = Eigen::Vector2d(estimate.x, estimate.y);
  }
  const auto start = std::chrono::steady_clock::now();
  const visual_localization::LocalizationResult result = c.localizer->Localize(frame, prior);
  const double measured = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const VisualLocalizationParameters& v = parameters_.visual;
  std::normal_distribution<double> normal(0.0, 1.0);
  const double drawn = std::min(v.latency_max, v.latency_median * std::exp(v.latency_log_sigma * normal(c.latency_rng)));
  const double latency = v.measured_latency ? measured : drawn;
  localizer_busy_until_ = frame.stamp + latency;  // one frame at a time
  next_localization_ = frame.stamp + 1.0 / v.rate_hz;
  ++telemetry_.visual.attempts;
  telemetry_.timings.visual_frames.push_back(result.timings);
  if (!result.success) {
    ++telemetry_.visual.failures;
    return;
  }
  ++telemetry_.visual.fixes;
  messages::PoseFix fix;
  fix.stamp = frame.stamp;
  const Pose2 planar = ToPose2(result.T_map_base);
  fix.x = planar.x;
  fix.y = planar.y;
  fix.yaw = planar.yaw;
  fix.covariance = result.planar_covariance;
  pending_fixes_.push_back({frame.stamp + latency, fix});
}

void RobotStack::DeliverVisualFixes(double stamp) {
  telemetry_.visual_fixes.clear();
  for (auto it = pending_fixes_.begin(); it != pending_fixes_.end();) {
    if (it->ready > stamp + 1e-12) {
      ++it;
      continue;
    }
    {
      ScopedTimer timer(&telemetry_.timings.ekf);
      components_->ekf.AddPoseFix(it->fix);
    }
    telemetry_.visual_fixes.push_back(it->fix);
    it = pending_fixes_.erase(it);
  }
}

bool RobotStack::LocalizationLost() const {
  if (parameters_.localization != LocalizationSource::kVisual) return false;
  const Eigen::Matrix2d position = components_->ekf.Estimate().covariance.topLeftCorner<2, 2>();
  const double sigma = std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(position).eigenvalues().maxCoeff());
  return sigma > parameters_.visual.max_position_sigma;
}

messages::RobotCommands RobotStack::Update(double stamp) {
  Components& c = *components_;
  messages::RobotCommands commands;
  telemetry_.events.clear();
  telemetry_.registration = std::move(pending_registration_);
  pending_registration_.reset();
  DeliverVisualFixes(stamp);
  if (stamp + 1e-9 >= next_control_) {
    // Control ticks at whole multiples of the period (no drift from summing periods).
    next_control_ = (std::floor((stamp + 1e-9) * parameters_.control_rate_hz) + 1.0) / parameters_.control_rate_hz;
    RunNavigation(stamp, &commands);
  }
  telemetry_.stamp = stamp;
  telemetry_.estimate = c.ekf.Estimate();
  telemetry_.odometry = ToPose2(ToIsometry(c.odom_origin) * ToIsometry(c.odometry.pose()));
  telemetry_.localization = c.ekf.counters();
  return commands;
}

void RobotStack::RunNavigation(double stamp, messages::RobotCommands* commands) {
  if (teleop_) {
    commands->base = *teleop_;
    last_linear_command_ = teleop_->linear;
    return;
  }
  Navigator* navigator = components_->navigator.get();
  if (navigator == nullptr) return;
  const double planning_before = navigator->planning_seconds();
  const auto start = std::chrono::steady_clock::now();
  if (LocalizationLost()) {
    // Better to stand than to drive blind: wait for the localization to come back.
    commands->base = messages::BaseVelocityCommand{};
    last_linear_command_ = 0.0;
    ++telemetry_.visual.stopped_updates;
    return;
  }
  commands->base = navigator->Update(stamp, components_->ekf.Estimate().pose);
  last_linear_command_ = commands->base ? commands->base->linear : 0.0;
  telemetry_.events = navigator->TakeEvents();
  telemetry_.mission = ToMission(navigator->mode());
  telemetry_.current_goal = navigator->current_goal();
  const double planning = navigator->planning_seconds() - planning_before;
  telemetry_.timings.planning += planning;
  telemetry_.timings.control += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - planning;
}

}  // namespace trimbot::stack
