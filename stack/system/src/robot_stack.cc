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
#include "trimbot/stack/bush_servo.h"
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

// The frame holds camera `camera`'s image (a driver delivers only what was asked for, and cameras drop out).
bool Delivered(const messages::RingFrame& frame, int camera) {
  return std::any_of(frame.images.begin(), frame.images.end(),
                     [camera](const messages::Image& image) { return image.camera_index == camera; });
}

// The cameras of stereo pairs, at the resolution stereo rectifies with (the calibration's).
messages::RingRequest PairsRequest(const std::vector<robot::StereoPair>& pairs) {
  messages::RingRequest request;
  for (const robot::StereoPair& pair : pairs) {
    request.cameras.push_back(pair.left);
    request.cameras.push_back(pair.right);
  }
  std::sort(request.cameras.begin(), request.cameras.end());
  request.resolution_scale = 1.0;
  return request;
}

bool HasBushGoal(const std::vector<Goal>& goals) {
  return std::any_of(goals.begin(), goals.end(), [](const Goal& g) { return g.bush.has_value(); });
}

// A planar point through a (planar) transform.
Eigen::Vector2d Apply(const Eigen::Isometry3d& T, const Eigen::Vector2d& p) {
  return (T * Eigen::Vector3d(p.x(), p.y(), 0.0)).head<2>();
}

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
    case MissionState::kReaching: return "reaching";
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
  GyroOdometry servo_odometry;                    // the bush servo's frame
  Ekf ekf;
  Pose2 odom_origin;                              // map pose of the odom frame
  std::unique_ptr<OccupancyGrid> map;
  std::unique_ptr<Navigator> navigator;
  std::unique_ptr<perception::LocalFusion> fusion;
  std::unique_ptr<perception::RingStereo> obstacle_stereo;  // with obstacle detection on
  std::unique_ptr<ObstacleLayer> obstacle_layer;            // made with the map
  std::unique_ptr<visual_localization::VisualLocalizer> localizer;
  Eigen::Vector2d arm_axis;                                 // base_link: the arm's base (the ring's centre)
  std::unique_ptr<perception::RingStereo> bush_stereo;      // made with a mission that has bush goals
  BushServo servo;
  arm::ArmExecutive arm;
  std::unique_ptr<perception::RingStereo> arm_stereo;       // made with arm goals
  Rng latency_rng;

  Components(const robot::RobotFiles& files, const StackParameters& parameters)
      : description(robot::RobotDescription::Load(files.urdf)),
        rig(robot::CameraRig::LoadKalibr(files.camchain,
                                         description.FramePose(robot::RobotFrames::CameraOptical(0)))),
        ticks_per_revolution(robot::RobotParameters::Load(files.robot_parameters).wheel_encoders.ticks_per_revolution),
        odometry(description.drive(), ticks_per_revolution),
        servo_odometry(description.drive(), ticks_per_revolution),
        ekf(parameters.ekf, description.drive(), ticks_per_revolution),
        arm_axis(description.FramePose(robot::RobotFrames::kCameraRing).translation().head<2>()),
        servo(parameters.bush_approach.servo, arm_axis),
        arm(description, parameters.arm),
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
  // The standoff must leave the footprint's front clear of the bush's surveyed outline.
  const Footprint& footprint = parameters_.navigation.planner.footprint;
  const double front = *std::max_element(footprint.circle_x.begin(), footprint.circle_x.end()) +
                       footprint.circle_radius - components_->arm_axis.x();
  if (parameters_.bush_approach.servo.surface_gap < front + parameters_.navigation.stop_clearance) {
    throw std::invalid_argument("stack parameters: bush_approach.servo.surface_gap must be at least " +
                                std::to_string(front + parameters_.navigation.stop_clearance) +
                                " m (the footprint's front from the arm's axis, plus navigation.stop_clearance)");
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

Goal Goal::ApproachBush(const Eigen::Vector2d& centre, const perception::BushShape& shape) {
  Goal goal(centre);
  goal.bush = shape;
  return goal;
}

bool RobotStack::UsesRingImages(const StackParameters& parameters, const std::vector<Goal>& goals, bool arm_goals) {
  return parameters.UsesRingImages() || HasBushGoal(goals) || arm_goals;
}

void RobotStack::SetArmGoals(const std::vector<Eigen::Isometry3d>& cutter_poses) {
  components_->arm.SetGoals(cutter_poses);
  arm_mission_ = !cutter_poses.empty();
  if (arm_mission_ && !components_->arm_stereo) {
    components_->arm_stereo = std::make_unique<perception::RingStereo>(components_->rig, perception::StereoOptions{});
  }
}

void RobotStack::SetGoals(const std::vector<Goal>& goals) {
  if (!components_->navigator) throw std::logic_error("RobotStack::SetGoals: no map (call SetMap first)");
  if (parameters_.localization == LocalizationSource::kVisual && !components_->localizer) {
    throw std::logic_error("RobotStack::SetGoals: localization is visual but no visual map was given (SetVisualMap)");
  }
  mission_ = goals;
  next_goal_ = 0;
  mission_failed_ = false;
  if (HasBushGoal(goals) && !components_->bush_stereo) {
    components_->bush_stereo = std::make_unique<perception::RingStereo>(components_->rig, perception::StereoOptions{});
  }
  StartSegment();
  teleop_.reset();
}

Eigen::Vector2d RobotStack::ApproachPoint(const Goal& goal, const Eigen::Vector2d& from) const {
  // base_link's position from which, turned to face the bush, the arm's axis is approach_margin
  // beyond the standoff. Of the sides of the bush where the footprint at the
  // standoff clears the map (other than the bush), the nearest to where the robot comes from whose
  // approach point can be arrived at from any direction (RRT* reaches a goal only along an edge
  // from its nearest node, so a goal some headings cannot arrive at makes it fail at random);
  // failing that, one the planner accepts at all.
  const Components& c = *components_;
  const Navigator& navigator = *c.navigator;
  const double standoff = goal.bush->Radius() + parameters_.bush_approach.servo.surface_gap;
  const double reach = standoff + parameters_.bush_approach.approach_margin + c.arm_axis.x();
  // Sides every 10 deg; a box only towards its corners (+-15 deg), where two faces show: seen
  // face-on, a box's centre along the face rests on its two leafy edges alone (3 deg off measured).
  std::vector<double> sides;
  if (goal.bush->kind == perception::BushShape::Kind::kBox) {
    for (int k = 0; k < 4; ++k) {
      for (double offset : {0.0, -15.0, 15.0}) sides.push_back(goal.bush->yaw + (45.0 + 90.0 * k + offset) * M_PI / 180.0);
    }
  } else {
    for (int k = 0; k < 36; ++k) sides.push_back(2.0 * M_PI * k / 36.0);
  }
  for (const double clearance : {navigator.ArrivalClearance(), parameters_.navigation.planner.robot_radius}) {
    std::optional<Eigen::Vector2d> best;
    for (const double angle : sides) {
      const Eigen::Vector2d side(std::cos(angle), std::sin(angle));
      const Eigen::Vector2d approach = goal.position + reach * side;
      const Eigen::Vector2d at_standoff = goal.position + (standoff + c.arm_axis.x()) * side;
      const Pose2 facing{at_standoff.x(), at_standoff.y(), angle + M_PI};
      if (navigator.costmap().DistanceToObstacle(approach) < clearance ||
          navigator.FootprintClearance(facing) < 2.0 * parameters_.navigation.stop_clearance) {
        continue;
      }
      if (!best || (approach - from).norm() < (*best - from).norm()) best = approach;
    }
    if (best) return *best;
  }
  // No side is free: straight from where the robot comes (the navigator moves the point or says why).
  const Eigen::Vector2d away = (from - goal.position).norm() > 1e-6 ? (from - goal.position).normalized()
                                                                      : Eigen::Vector2d(-1.0, 0.0);
  return goal.position + reach * away;
}

void RobotStack::StartSegment() {
  Components& c = *components_;
  const Pose2 estimate = c.ekf.Estimate().pose;
  Eigen::Vector2d from(estimate.x, estimate.y);
  std::vector<Eigen::Vector2d> points;
  bush_goal_ = -1;
  servoing_ = false;
  for (int i = next_goal_; i < static_cast<int>(mission_.size()); ++i) {
    const Goal& goal = mission_[static_cast<std::size_t>(i)];
    if (goal.bush) {
      points.push_back(ApproachPoint(goal, from));
      bush_goal_ = i;
      break;
    }
    points.push_back(goal.position);
    from = goal.position;
  }
  c.navigator->SetGoals(points, next_goal_);
  if (bush_goal_ >= 0) {
    const Goal& goal = mission_[static_cast<std::size_t>(bush_goal_)];
    c.servo.Expect(Apply(MapFromServoFrame().inverse(), goal.position), goal.bush->Radius());
    bush_status_ = BushApproachStatus{};
    bush_status_.goal = bush_goal_;
    bush_status_.target_distance = c.servo.target_distance();
    bush_status_.target_bearing = parameters_.bush_approach.servo.bearing;
  }
}

void RobotStack::SetTeleopCommand(const messages::BaseVelocityCommand& command) { teleop_ = command; }

void RobotStack::Add(const messages::ImuSample& imu) {
  ScopedTimer timer(&telemetry_.timings.ekf);
  components_->ekf.AddImu(imu);
  if (components_->ekf.initialized()) {
    components_->servo_odometry.AddYawRate(imu.stamp, imu.angular_velocity.z() - components_->ekf.Estimate().gyro_bias);
  }
}

void RobotStack::Add(const messages::WheelTicks& ticks) {
  ScopedTimer timer(&telemetry_.timings.ekf);
  components_->ekf.AddWheelTicks(ticks);
  components_->odometry.Update(ticks);
  components_->servo_odometry.AddWheelTicks(ticks);
}

void RobotStack::Add(const messages::ArmJointState& joints) { components_->arm.SetJointState(joints); }

void RobotStack::Add(const messages::RingFrame& frame) {
  ++telemetry_.ring_frames;
  if (VisualLocalizationDue(frame.stamp)) LocalizeVisually(frame);
  if (ObstacleDetectionDue(frame.stamp)) DetectObstacles(frame);
  if (BushSightingDue(frame.stamp)) LookForBush(frame);
  if (ArmEnvironmentDue()) PerceiveArmEnvironment(frame);
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
    std::vector<robot::StereoPair> ahead;
    for (int pair : PairsAhead()) {
      ahead.push_back(components_->obstacle_stereo->rectifiers()[static_cast<std::size_t>(pair)].pair());
    }
    request = messages::Merge(request, PairsRequest(ahead));
  }
  if (BushSightingDue(stamp)) {
    const auto& facing = components_->bush_stereo->rectifiers()[static_cast<std::size_t>(*PairFacingBush())];
    request = messages::Merge(request, PairsRequest({facing.pair()}));
  }
  if (ArmEnvironmentDue()) request = messages::Merge(request, PairsRequest(components_->rig.StereoPairs()));
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
    if (!Delivered(frame, rectifier.pair().left) || !Delivered(frame, rectifier.pair().right)) continue;
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

Eigen::Isometry3d RobotStack::MapFromServoFrame() const {
  // The EKF's map pose of base_link and the gyro odometry's pose of it, at the same time.
  return ToIsometry(components_->ekf.Estimate().pose) * ToIsometry(components_->servo_odometry.pose()).inverse();
}

Eigen::Vector2d RobotStack::ExpectedBushInBase() const {
  const Components& c = *components_;
  if (c.servo.tracking()) return IntoFrame(c.servo_odometry.pose(), c.servo.centre());
  return IntoFrame(c.ekf.Estimate().pose, mission_[static_cast<std::size_t>(bush_goal_)].position);
}

std::optional<int> RobotStack::PairFacingBush() const {
  if (bush_goal_ < 0 || !components_->bush_stereo) return std::nullopt;
  const Eigen::Vector2d bush = ExpectedBushInBase();
  if ((bush - components_->arm_axis).norm() > parameters_.bush_approach.sighting_range) return std::nullopt;
  std::optional<int> best;
  double best_angle = parameters_.bush_approach.max_bearing;
  const auto& rectifiers = components_->bush_stereo->rectifiers();
  for (std::size_t i = 0; i < rectifiers.size(); ++i) {
    const Eigen::Isometry3d& T = rectifiers[i].T_base_rectified_left();
    const Eigen::Vector2d axis = T.linear().col(2).head<2>(), to_bush = bush - T.translation().head<2>();
    const double angle = std::abs(std::remainder(std::atan2(to_bush.y(), to_bush.x()) - std::atan2(axis.y(), axis.x()),
                                                 2.0 * M_PI));
    if (angle <= best_angle) {
      best_angle = angle;
      best = static_cast<int>(i);
    }
  }
  return best;
}

bool RobotStack::BushSightingDue(double stamp) const {
  return bush_goal_ >= 0 && stamp + 1e-9 >= next_bush_frame_ && PairFacingBush().has_value();
}

void RobotStack::LookForBush(const messages::RingFrame& frame) {
  ScopedTimer timer(&telemetry_.timings.bush);
  Components& c = *components_;
  const int pair = *PairFacingBush();
  const perception::StereoRectifier& rectifier = c.bush_stereo->rectifiers()[static_cast<std::size_t>(pair)];
  if (!Delivered(frame, rectifier.pair().left) || !Delivered(frame, rectifier.pair().right)) return;
  next_bush_frame_ = frame.stamp + 1.0 / parameters_.bush_approach.rate_hz;
  ++telemetry_.timings.bush_frames;
  BushSighting sighting;
  sighting.stamp = frame.stamp;
  sighting.goal = bush_goal_;
  const Goal& goal = mission_[static_cast<std::size_t>(bush_goal_)];
  if (!c.servo.tracking()) {
    // The map's belief through the pose estimate now (odometry's heading drifts in turns).
    c.servo.Expect(Apply(MapFromServoFrame().inverse(), goal.position), goal.bush->Radius());
  }
  const perception::PointCloud cloud = c.bush_stereo->ComputePair(frame, pair).cloud;
  const auto ground = perception::FitGroundPlane(cloud);
  perception::BushShape shape = *goal.bush;
  shape.yaw -= c.ekf.Estimate().pose.yaw;  // map -> base_link
  const auto estimate = perception::FitBush(cloud, ground.value_or(perception::GroundPlane{}), shape,
                                            ExpectedBushInBase(), parameters_.bush_approach.fit, &sighting.failure);
  ++bush_status_.frames;
  if (estimate) {
    sighting.found = true;
    sighting.centre_base = estimate->centre;
    sighting.scale = estimate->scale;
    sighting.points = estimate->points;
    const Eigen::Vector2d from_arm = estimate->centre - c.arm_axis;
    sighting.distance = from_arm.norm();
    sighting.bearing = std::atan2(from_arm.y(), from_arm.x());
    // The odometry pose at the frame: wheel ticks up to the frame have been added.
    sighting.tracked = c.servo.AddMeasurement(frame.stamp, c.servo_odometry.pose(), estimate->centre);
    if (!sighting.tracked) sighting.failure = "too far from the track";
    bush_status_.tracked += sighting.tracked ? 1 : 0;
  } else {
    c.servo.AddMiss(frame.stamp);
  }
  pending_sightings_.push_back(std::move(sighting));
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
  const double drawn = std::min(v.latency_max, v.latency_median * std::exp(v.latency_log_sigma * StandardNormal(c.latency_rng)));
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
  telemetry_.bush_sightings = std::move(pending_sightings_);
  telemetry_.arm_results.clear();
  pending_sightings_.clear();
  DeliverVisualFixes(stamp);
  if (stamp + 1e-9 >= next_control_) {
    // Control ticks at whole multiples of the period (no drift from summing periods).
    next_control_ = (std::floor((stamp + 1e-9) * parameters_.control_rate_hz) + 1.0) / parameters_.control_rate_hz;
    RunNavigation(stamp, &commands);
    if (arm_mission_) RunArm(stamp, &commands);
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
  if (servoing_) {
    // On odometry and stereo alone: the servo needs no map pose.
    RunBushServo(stamp, commands);
  } else if (LocalizationLost()) {
    // Better to stand than to drive blind: wait for the localization to come back.
    commands->base = messages::BaseVelocityCommand{};
    ++telemetry_.visual.stopped_updates;
  } else {
    commands->base = navigator->Update(stamp, components_->ekf.Estimate().pose);
    telemetry_.events = navigator->TakeEvents();
    HandleNavigationEvents(stamp);
  }
  last_linear_command_ = commands->base ? commands->base->linear : 0.0;
  UpdateMissionTelemetry();
  const double planning = navigator->planning_seconds() - planning_before;
  telemetry_.timings.planning += planning;
  telemetry_.timings.control += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - planning;
}

void RobotStack::HandleNavigationEvents(double stamp) {
  for (NavigationEvent& event : telemetry_.events) {
    if (event.type != NavigationEvent::Type::kGoalReached || event.goal != bush_goal_) continue;
    // By map at the bush's approach point: the bush goal itself is reached by visual servoing.
    event.type = NavigationEvent::Type::kApproachReached;
    servoing_ = true;
    components_->servo.Start(stamp);
  }
}

void RobotStack::RunBushServo(double stamp, messages::RobotCommands* commands) {
  BushServo& servo = components_->servo;
  commands->base = servo.Update(stamp, components_->servo_odometry.pose());
  if (servo.mode() == BushServo::Mode::kDone) {
    const Eigen::Vector2d db = servo.DistanceBearing(components_->servo_odometry.pose());
    FinishBushGoal(stamp, true, std::to_string(db.x()) + " m, " + std::to_string(db.y() * 180.0 / M_PI) + " deg");
  } else if (servo.mode() == BushServo::Mode::kFailed) {
    FinishBushGoal(stamp, false, servo.failure());
  }
}

void RobotStack::FinishBushGoal(double stamp, bool reached, const std::string& detail) {
  NavigationEvent event;
  event.stamp = stamp;
  event.type = reached ? NavigationEvent::Type::kGoalReached : NavigationEvent::Type::kGoalFailed;
  event.goal = bush_goal_;
  event.detail = detail;
  event.position = Apply(MapFromServoFrame(), components_->servo.centre());  // the bush's centre as tracked
  telemetry_.events.push_back(event);
  servoing_ = false;
  if (!reached) {
    mission_failed_ = true;
    return;
  }
  next_goal_ = bush_goal_ + 1;
  StartSegment();  // the rest of the mission (none: the navigator is done)
}

void RobotStack::UpdateMissionTelemetry() {
  const Navigator& navigator = *components_->navigator;
  telemetry_.mission = mission_failed_ ? MissionState::kFailed
                       : servoing_     ? MissionState::kDriving
                                       : ToMission(navigator.mode());
  telemetry_.current_goal = servoing_ || mission_failed_ ? bush_goal_ : navigator.current_goal();
  if (bush_goal_ < 0) {
    telemetry_.bush.reset();
    return;
  }
  const BushServo& servo = components_->servo;
  bush_status_.mode = servoing_ ? ToString(servo.mode()) : "navigating";
  const Eigen::Vector2d db = servo.DistanceBearing(components_->servo_odometry.pose());
  bush_status_.distance = db.x();
  bush_status_.bearing = db.y();
  telemetry_.bush = bush_status_;
}

bool RobotStack::NavigationGoalsDone() const {
  return mission_.empty() || telemetry_.mission == MissionState::kDone || telemetry_.mission == MissionState::kReaching;
}

bool RobotStack::ArmEnvironmentDue() const {
  if (!arm_mission_ || !components_->arm.WantsEnvironment()) return false;
  return NavigationGoalsDone() && std::abs(last_linear_command_) < 1e-9;
}

void RobotStack::PerceiveArmEnvironment(const messages::RingFrame& frame) {
  ScopedTimer timer(&telemetry_.timings.arm);
  Components& c = *components_;
  perception::PointCloud seen;
  for (std::size_t pair = 0; pair < c.arm_stereo->rectifiers().size(); ++pair) {
    const robot::StereoPair& cameras = c.arm_stereo->rectifiers()[pair].pair();
    if (!Delivered(frame, cameras.left) || !Delivered(frame, cameras.right)) continue;
    const perception::PointCloud cloud = c.arm_stereo->ComputePair(frame, static_cast<int>(pair)).cloud;
    for (std::size_t i = 0; i < cloud.size(); ++i) seen.Add(cloud.points[i], cloud.covariances[i]);
  }
  if (seen.empty()) return;  // no pair delivered: the next frame
  c.arm.SetPerceivedPoints(seen.points, seen.covariances);
  ++telemetry_.timings.arm_frames;
}

void RobotStack::RunArm(double stamp, messages::RobotCommands* commands) {
  ScopedTimer timer(&telemetry_.timings.arm);
  arm::ArmExecutive& arm = components_->arm;
  if (telemetry_.mission == MissionState::kFailed || !NavigationGoalsDone()) return;
  if (auto command = arm.Update(stamp)) commands->arm = *command;
  telemetry_.arm_results = arm.TakeResults();
  ArmStatus status;
  status.mode = arm::ToString(arm.mode());
  status.goal = arm.current_goal();
  status.perceived_cells = arm.perceived_cells();
  status.target.assign(arm.target().data(), arm.target().data() + arm.target().size());
  telemetry_.arm = status;
  telemetry_.mission = arm.mode() == arm::ArmExecutive::Mode::kDone ? MissionState::kDone : MissionState::kReaching;
}

}  // namespace trimbot::stack
