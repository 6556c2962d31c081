#include "trimbot/sim/simulator.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "trimbot/common/input_error.h"
#include "trimbot/common/random.h"
#include "trimbot/sim/arm_controller.h"
#include "trimbot/sim/base_controller.h"
#include "trimbot/sim/camera_exposure.h"
#include "trimbot/sim/camera_noise.h"
#include "trimbot/sim/imu_model.h"
#include "trimbot/sim/motion_blur.h"
#include "trimbot/sim/ring_renderer.h"
#include "trimbot/sim/weather.h"
#include "trimbot/sim/wheel_encoder_model.h"
#include "trimbot/sim/world.h"

namespace trimbot::sim {

using robot::RobotFrames;

namespace {

// The garden's objects plus the configuration's extra ones.
garden::Garden GardenWithExtraObjects(const SimulatorConfig& config) {
  garden::Garden garden = config.garden;
  try {
    garden.AddObjects(config.extra_objects);
  } catch (const std::invalid_argument& e) {
    throw InputError(garden.source.empty() ? garden.name : garden.source, std::string("an extra object: ") + e.what());
  }
  return garden;
}

// Number of physics steps per sensor sample; the rate must divide the physics rate.
int StepsPerSample(double rate_hz, double timestep, const std::string& file, const std::string& sensor) {
  const double steps = 1.0 / (rate_hz * timestep);
  const long rounded = std::lround(steps);
  if (rounded < 1 || std::abs(steps - static_cast<double>(rounded)) > 1e-6) {
    throw InputError(file, sensor + " rate " + std::to_string(rate_hz) + " Hz is not the physics rate (" +
                               std::to_string(1.0 / timestep) + " Hz) divided by a whole number");
  }
  return static_cast<int>(rounded);
}

Eigen::Isometry3d PoseFromMujoco(const mjtNum* pos, const mjtNum* mat) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() << pos[0], pos[1], pos[2];
  pose.linear() << mat[0], mat[1], mat[2], mat[3], mat[4], mat[5], mat[6], mat[7], mat[8];
  return pose;
}

// The velocity of a camera (optical frame) fixed on the base at T_base_camera.
CameraTwist CameraTwistOf(const GroundTruth& truth, const Eigen::Isometry3d& T_base_camera) {
  const Eigen::Matrix3d R_camera_base = T_base_camera.linear().transpose();
  CameraTwist twist;
  twist.linear =
      R_camera_base * (truth.linear_velocity_base + truth.angular_velocity_base.cross(T_base_camera.translation()));
  twist.angular = R_camera_base * truth.angular_velocity_base;
  return twist;
}

}  // namespace

// A plant's mesh as built, and how it moves in the wind.
struct AnimatedPlant {
  int mesh = -1;
  PlantMotion motion;
  Eigen::Matrix3d R_world_mesh;
  std::vector<Eigen::Vector3d> rest_in_world;
  std::vector<float> rest;      // mjModel::mesh_vert as built
  std::vector<float> vertices;  // as drawn now
};

// A cuttable topiary: its foliage, and its drawn mesh's vertices as directions from the foliage's
// centre (the mesh is redrawn with each vertex at most where the foliage now ends).
struct CuttableTopiary {
  int object_id = 0;
  garden::Foliage foliage;
  int mesh = -1;
  Eigen::Isometry3d T_mesh_centre = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3d> rest_in_centre;  // the vertices as built, in the centre frame
  long drawn_cuts = 0;                          // foliage.cut_columns() when last drawn
};

struct Simulator::Impl {
  std::unique_ptr<World> world;
  std::unique_ptr<RingRenderer> renderer;
  std::unique_ptr<GustyWind> wind;
  std::vector<AnimatedPlant> plants;
  std::unique_ptr<CloudShadows> clouds;
  MotionBlur motion_blur;
  double weather_time = -1.0;  // the time the plants and the sun were last set for
  std::unique_ptr<ReadNoise> read_noise;
  std::unique_ptr<BaseController> base;
  std::unique_ptr<ArmController> arm;
  std::unique_ptr<ImuModel> imu;
  std::unique_ptr<WheelEncoderModel> encoders;
  bool cutter_on = false;
  std::vector<CuttableTopiary> topiaries;
  std::optional<garden::BladeDisc> last_blade;  // the blade at the end of the last step
  Eigen::Isometry3d T_cutter_blade = Eigen::Isometry3d::Identity();
  double blade_radius = 0.0;
  long step = 0;
  long frame = 0;
  int imu_steps = 1, encoder_steps = 1, camera_steps = 1;
  double last_left_angle = 0.0, last_right_angle = 0.0;
  garden::SlipModel ground_slip[4];
  std::vector<bool> fault_applied;
  int end_effector_body = -1;
  SimulatorTimings timings;  // physics and exposure/noise here; the renderer keeps its own
};

Simulator::Simulator(const SimulatorConfig& config)
    : config_(config),
      robot_(robot::RobotDescription::Load(config.robot.urdf)),
      parameters_(robot::RobotParameters::Load(config.robot.robot_parameters)),
      rig_(robot::CameraRig::LoadKalibr(config.robot.camchain, robot_.FramePose(RobotFrames::CameraOptical(0)))),
      garden_(GardenWithExtraObjects(config)),
      impl_(std::make_unique<Impl>()) {
  if (rig_.size() != 10) {
    throw InputError(config.robot.camchain,
                     "the ring needs 10 cameras, the calibration has " + std::to_string(rig_.size()));
  }
  WorldOptions options;
  options.timestep = config.timestep;
  options.start = config.start;
  options.conditions = config.conditions;
  options.msaa_samples = config.msaa_samples;
  options.cuttable_objects = config.cuttable_objects;
  spec_ = ComposeWorld(robot_, rig_, garden_, options, config.world_dir);
  impl_->world = std::make_unique<World>(spec_);

  const std::string& params = config.robot.robot_parameters;
  impl_->imu_steps = StepsPerSample(parameters_.imu.rate_hz, config.timestep, params, "IMU");
  impl_->encoder_steps = StepsPerSample(parameters_.wheel_encoders.rate_hz, config.timestep, params, "wheel encoder");
  impl_->camera_steps = StepsPerSample(parameters_.cameras.rate_hz, config.timestep, params, "camera");

  impl_->base = std::make_unique<BaseController>(robot_.drive(), parameters_.drive);
  for (double* p : {&parameters_.imu.accelerometer_noise_density, &parameters_.imu.accelerometer_random_walk,
                    &parameters_.imu.accelerometer_initial_bias_sigma, &parameters_.imu.gyroscope_noise_density,
                    &parameters_.imu.gyroscope_random_walk, &parameters_.imu.gyroscope_initial_bias_sigma}) {
    *p *= config.imu_noise_scale;
  }
  impl_->imu = std::make_unique<ImuModel>(parameters_.imu, config.seed);
  impl_->encoders = std::make_unique<WheelEncoderModel>(parameters_.wheel_encoders.ticks_per_revolution, config.seed);
  for (auto surface :
       {garden::Surface::kGrass, garden::Surface::kGravel, garden::Surface::kPavement, garden::Surface::kSoil}) {
    garden::SlipModel& slip = impl_->ground_slip[static_cast<int>(surface)];
    slip = garden::PropertiesOf(surface).slip;
    slip.mean *= config.wheel_slip_scale;
    slip.sigma *= config.wheel_slip_scale;
  }

  // The arm starts in its home pose, held by its servos.
  mjModel* m = impl_->world->model();
  mjData* d = impl_->world->data();
  std::array<JointRange, messages::kArmJoints> ranges{};
  for (size_t i = 0; i < ranges.size(); ++i) {
    const auto& joint = impl_->world->arm()[i];
    d->qpos[joint.qpos] = parameters_.arm_home_position[i];
    ranges[i] = {m->jnt_limited[joint.joint] != 0, m->jnt_range[2 * joint.joint], m->jnt_range[2 * joint.joint + 1]};
  }
  impl_->arm = std::make_unique<ArmController>(parameters_.arm_home_position, ranges);
  mj_forward(m, d);

  impl_->end_effector_body = mj_name2id(m, mjOBJ_BODY, RobotFrames::kEndEffector);
  impl_->fault_applied.assign(config.faults.size(), false);
  if (config.render_cameras) {
    impl_->renderer = std::make_unique<RingRenderer>(*impl_->world, rig_, config.frustum_culling);
    impl_->read_noise = std::make_unique<ReadNoise>(StreamSeed(config.seed, "camera_read_noise"));
    SetUpWeather();
  }
  SetUpFoliage();
}

void Simulator::SetUpFoliage() {
  impl_->T_cutter_blade = robot_.BladeInCutter();
  impl_->blade_radius = robot_.BladeRadius();
  const World& world = *impl_->world;
  const mjModel* m = world.model();
  const mjData* d = world.data();
  for (const int id : config_.cuttable_objects) {
    const auto object = std::find_if(garden_.objects.begin(), garden_.objects.end(),
                                     [&](const garden::GardenObject& o) { return o.id == id; });
    if (object == garden_.objects.end() || object->object_class != garden::ObjectClass::kTopiary) {
      throw std::invalid_argument("Simulator: object " + std::to_string(id) + " is not a topiary of the garden");
    }
    CuttableTopiary topiary;
    topiary.object_id = id;
    topiary.foliage = garden::Foliage::Grown(*object, garden_.appearance_seed, config_.conditions.growth);
    for (int g = 0; g < m->ngeom; ++g) {
      const GeomLabel* label = world.label(g);
      if (label == nullptr || label->object_id != id || m->geom_type[g] != mjGEOM_MESH || m->geom_contype[g] != 0) {
        continue;
      }
      topiary.mesh = m->geom_dataid[g];
      const Eigen::Isometry3d T_map_mesh = PoseFromMujoco(d->geom_xpos + 3 * g, d->geom_xmat + 9 * g);
      topiary.T_mesh_centre = T_map_mesh.inverse() * topiary.foliage.pose();
      const float* vertex = m->mesh_vert + 3 * m->mesh_vertadr[topiary.mesh];
      for (int v = 0; v < m->mesh_vertnum[topiary.mesh]; ++v) {
        topiary.rest_in_centre.push_back(topiary.T_mesh_centre.inverse() *
                                         Eigen::Vector3d(vertex[3 * v], vertex[3 * v + 1], vertex[3 * v + 2]));
      }
    }
    impl_->topiaries.push_back(std::move(topiary));
  }
}

void Simulator::CutFoliage(const GroundTruth& truth) {
  if (impl_->topiaries.empty()) return;
  const Eigen::Isometry3d T_map_blade = truth.T_map_end_effector * impl_->T_cutter_blade;
  garden::BladeDisc blade;
  blade.centre = T_map_blade.translation();
  blade.axis = T_map_blade.linear().col(2);
  blade.radius = impl_->blade_radius;
  if (impl_->cutter_on && impl_->last_blade) {
    for (CuttableTopiary& topiary : impl_->topiaries) topiary.foliage.Cut(*impl_->last_blade, blade);
  }
  impl_->last_blade = blade;
}

void Simulator::DrawCutFoliage() {
  if (!impl_->renderer) return;
  for (CuttableTopiary& topiary : impl_->topiaries) {
    if (topiary.mesh < 0 || topiary.foliage.cut_columns() == topiary.drawn_cuts) continue;
    topiary.drawn_cuts = topiary.foliage.cut_columns();
    std::vector<float> vertices(3 * topiary.rest_in_centre.size());
    for (std::size_t v = 0; v < topiary.rest_in_centre.size(); ++v) {
      const Eigen::Vector3d now = topiary.T_mesh_centre * topiary.foliage.CutBack(topiary.rest_in_centre[v]);
      for (int k = 0; k < 3; ++k) vertices[3 * v + static_cast<std::size_t>(k)] = static_cast<float>(now[k]);
    }
    // A plant that sways sways about its cut shape.
    const auto plant = std::find_if(impl_->plants.begin(), impl_->plants.end(),
                                    [&](const AnimatedPlant& p) { return p.mesh == topiary.mesh; });
    if (plant != impl_->plants.end()) {
      const Eigen::Matrix3d& R = plant->R_world_mesh;
      for (std::size_t v = 0; v < topiary.rest_in_centre.size(); ++v) {
        const Eigen::Vector3d now(vertices[3 * v], vertices[3 * v + 1], vertices[3 * v + 2]);
        const Eigen::Vector3d was(plant->rest[3 * v], plant->rest[3 * v + 1], plant->rest[3 * v + 2]);
        plant->rest_in_world[v] += R * (now - was);
      }
      plant->rest = vertices;
      impl_->weather_time = -1.0;  // moved again at the next draw
    } else {
      impl_->renderer->ReplaceMeshVertices(topiary.mesh, vertices);
    }
  }
}

const garden::Foliage* Simulator::foliage(int object_id) const {
  for (const CuttableTopiary& topiary : impl_->topiaries) {
    if (topiary.object_id == object_id) return &topiary.foliage;
  }
  return nullptr;
}

void Simulator::SetUpWeather() {
  impl_->clouds = std::make_unique<CloudShadows>(config_.conditions.clouds, StreamSeed(config_.seed, "clouds"));
  impl_->wind = std::make_unique<GustyWind>(config_.conditions.wind, StreamSeed(config_.seed, "wind"));
  if (config_.conditions.wind.mean_speed <= 0.0) return;
  const World& world = *impl_->world;
  const mjModel* m = world.model();
  const mjData* d = world.data();
  std::vector<double> margins(static_cast<std::size_t>(m->ngeom), 0.0);
  for (int g = 0; g < m->ngeom; ++g) {
    const GeomLabel* label = world.label(g);
    if (label == nullptr || label->is_ground || m->geom_type[g] != mjGEOM_MESH) continue;
    const auto found = std::find_if(garden_.objects.begin(), garden_.objects.end(),
                                    [&](const garden::GardenObject& o) { return o.id == label->object_id; });
    const garden::GardenObject* object = found == garden_.objects.end() ? nullptr : &*found;
    if (object == nullptr || MechanicsOf(object->object_class).sway_frequency <= 0.0) continue;
    const Eigen::Vector3d base(object->position.x(), object->position.y(), object->base_height);
    AnimatedPlant plant{m->geom_dataid[g],
                        PlantMotion(*impl_->wind, object->object_class, object->id, base, object->size.z()),
                        Eigen::Matrix3d::Identity(),
                        {},
                        {},
                        {}};
    const Eigen::Isometry3d pose = PoseFromMujoco(d->geom_xpos + 3 * g, d->geom_xmat + 9 * g);
    plant.R_world_mesh = pose.linear();
    const float* vertex = m->mesh_vert + 3 * m->mesh_vertadr[plant.mesh];
    plant.rest.assign(vertex, vertex + 3 * m->mesh_vertnum[plant.mesh]);
    for (int v = 0; v < m->mesh_vertnum[plant.mesh]; ++v) {
      plant.rest_in_world.push_back(pose * Eigen::Vector3d(vertex[3 * v], vertex[3 * v + 1], vertex[3 * v + 2]));
    }
    plant.vertices = plant.rest;
    margins[static_cast<std::size_t>(g)] = plant.motion.MaxDisplacement();
    impl_->plants.push_back(std::move(plant));
  }
  impl_->renderer->SetCullingMargins(std::move(margins));
}

void Simulator::SetWeatherFor(double t) {
  if (t == impl_->weather_time) return;
  impl_->weather_time = t;
  impl_->renderer->SetSunTransmittance(impl_->clouds->DirectTransmittance(t));
  const auto start = std::chrono::steady_clock::now();
  for (AnimatedPlant& plant : impl_->plants) {
    const Eigen::Matrix3d R_mesh_world = plant.R_world_mesh.transpose();
    for (std::size_t v = 0; v < plant.rest_in_world.size(); ++v) {
      const Eigen::Vector3d moved = R_mesh_world * plant.motion.Displacement(plant.rest_in_world[v], t);
      for (int k = 0; k < 3; ++k) plant.vertices[3 * v + k] = plant.rest[3 * v + k] + static_cast<float>(moved[k]);
    }
    impl_->renderer->ReplaceMeshVertices(plant.mesh, plant.vertices);
  }
  impl_->timings.wind += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Simulator::~Simulator() = default;

World& Simulator::world() { return *impl_->world; }

void Simulator::SetBaseCommand(const messages::BaseVelocityCommand& command) { impl_->base->SetCommand(command); }
void Simulator::SetArmCommand(const messages::ArmCommand& command) { impl_->arm->SetCommand(command); }
void Simulator::SetCutterCommand(const messages::CutterCommand& command) { impl_->cutter_on = command.on; }

void Simulator::Apply(const messages::RobotCommands& commands) {
  if (commands.base) SetBaseCommand(*commands.base);
  if (commands.arm) SetArmCommand(*commands.arm);
  if (commands.cutter) SetCutterCommand(*commands.cutter);
}

double Simulator::time() const { return impl_->world->data()->time; }

const garden::SlipModel* Simulator::SurfaceUnder(int wheel_geom) const {
  const World& world = *impl_->world;
  const mjData* d = world.data();
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& contact = d->contact[i];
    int other = -1;
    if (contact.geom1 == wheel_geom) other = contact.geom2;
    if (contact.geom2 == wheel_geom) other = contact.geom1;
    const GeomLabel* label = world.label(other);
    if (label != nullptr && label->is_ground) {
      const garden::Surface surface = garden_.SurfaceAt({contact.pos[0], contact.pos[1]});
      return &impl_->ground_slip[static_cast<int>(surface)];
    }
  }
  return nullptr;
}

void Simulator::Step(SensorOutputs* sensors, GroundTruth* truth) {
  const auto physics_start = std::chrono::steady_clock::now();
  World& world = *impl_->world;
  mjModel* m = world.model();
  mjData* d = world.data();
  const double dt = config_.timestep;

  // Actuation.
  impl_->base->Update(dt);
  const robot::WheelSpeeds setpoints =
      impl_->base->ActuatorSetpoints({d->qvel[world.left_wheel().dof], d->qvel[world.right_wheel().dof]}, dt);
  d->ctrl[world.left_wheel().actuator] = setpoints.left;
  d->ctrl[world.right_wheel().actuator] = setpoints.right;
  const auto& arm_target = impl_->arm->Update(dt);
  for (size_t i = 0; i < arm_target.size(); ++i) {
    const auto& joint = world.arm()[i];
    d->ctrl[joint.actuator] = arm_target[i];
    d->qfrc_applied[joint.dof] = d->qfrc_bias[joint.dof];  // the arm firmware's gravity compensation
  }
  d->ctrl[world.cutter().actuator] = impl_->cutter_on ? 300.0 : 0.0;

  const double stamp_before = d->time;
  const bool cameras_available = ApplyFaults();
  mj_step(m, d);
  ++impl_->step;
  ReadSensors(stamp_before, sensors);

  const bool ring_exposed = cameras_available && impl_->step % impl_->camera_steps == 0;
  *truth = ground_truth();
  CutFoliage(*truth);
  truth->contacts = ObstacleContacts();
  truth->arm_contacts = ArmContacts();
  truth->ring_exposed = ring_exposed;
  impl_->timings.physics += std::chrono::duration<double>(std::chrono::steady_clock::now() - physics_start).count();
  ++impl_->timings.physics_steps;
  std::optional<RingCapture> capture;
  if (ring_exposed && config_.render_cameras && config_.cameras_on_schedule) {
    const int every = config_.ground_truth_every_frames;
    capture = CaptureRing(every > 0 && impl_->frame % every == 0);
  }
  if (capture) {
    sensors->ring = std::move(capture->frame);
    truth->ring = std::move(capture->truth);
  }
}

void Simulator::ReadSensors(double stamp_before, SensorOutputs* sensors) {
  World& world = *impl_->world;
  const mjData* d = world.data();
  // IMU: MuJoCo's sensors were evaluated at the start of the step.
  if (impl_->step % impl_->imu_steps == 0) {
    const Eigen::Map<const Eigen::Vector3d> accel(d->sensordata + world.accelerometer_adr());
    const Eigen::Map<const Eigen::Vector3d> gyro(d->sensordata + world.gyro_adr());
    sensors->imu.push_back(impl_->imu->Measure(stamp_before, accel, gyro, impl_->imu_steps * config_.timestep));
  }

  // Encoders integrate every step (slip depends on the surface under each wheel).
  const double left_angle = d->qpos[world.left_wheel().qpos];
  const double right_angle = d->qpos[world.right_wheel().qpos];
  impl_->encoders->Advance(config_.timestep, left_angle - impl_->last_left_angle, right_angle - impl_->last_right_angle,
                           SurfaceUnder(world.left_wheel_geom()), SurfaceUnder(world.right_wheel_geom()));
  impl_->last_left_angle = left_angle;
  impl_->last_right_angle = right_angle;
  if (impl_->step % impl_->encoder_steps == 0) {
    sensors->wheel_ticks.push_back(impl_->encoders->Read(d->time));
    // The arm's joint encoders report with the wheels' (the Jaco's firmware is far finer than the
    // controllers' errors, so no noise is modelled).
    messages::ArmJointState joints;
    joints.stamp = d->time;
    for (size_t i = 0; i < joints.position.size(); ++i) {
      joints.position[i] = d->qpos[world.arm()[i].qpos];
      joints.velocity[i] = d->qvel[world.arm()[i].dof];
    }
    sensors->arm_joints.push_back(joints);
  }
}

bool Simulator::ApplyFaults() {
  const double t = impl_->world->data()->time;
  double slip_left = 0.0, slip_right = 0.0;
  bool cameras_available = true;
  for (std::size_t i = 0; i < config_.faults.size(); ++i) {
    const Fault& fault = config_.faults[i];
    switch (fault.kind) {
      case Fault::Kind::kWheelSlip:
        if (fault.ActiveAt(t)) {
          slip_left += fault.slip_left;
          slip_right += fault.slip_right;
        }
        break;
      case Fault::Kind::kImuBiasJump:
        if (!impl_->fault_applied[i] && t >= fault.start) {
          impl_->imu->AddGyroscopeBias(fault.gyroscope_bias_jump);
          impl_->imu->AddAccelerometerBias(fault.accelerometer_bias_jump);
          impl_->fault_applied[i] = true;
        }
        break;
      case Fault::Kind::kCameraDropout:
        if (fault.ActiveAt(t)) cameras_available = false;
        break;
    }
  }
  impl_->encoders->SetExtraSlip(slip_left, slip_right);
  return cameras_available;
}

SimulatorTimings Simulator::timings() const {
  SimulatorTimings out = impl_->timings;
  if (impl_->renderer) {
    const RenderTimings& r = impl_->renderer->timings();
    out.render_draw = r.draw;
    out.render_readback = r.readback;
    out.distortion = r.distortion;
    out.depth = r.depth;
    out.ground_truth = r.ground_truth;
    out.camera_images = r.images;
    out.geoms_drawn = r.geoms_in_view;
    out.geoms_culled = r.geoms_culled;
  }
  return out;
}

messages::RingRequest Simulator::WholeRing() const {
  messages::RingRequest all;
  for (int i = 0; i < rig_.size(); ++i) all.cameras.push_back(i);
  all.resolution_scale = config_.resolution_scale;
  return all;
}

RingCapture Simulator::CaptureRing(bool with_ground_truth) { return CaptureRing(WholeRing(), with_ground_truth); }

RingCapture Simulator::CaptureRing(const messages::RingRequest& request, bool with_ground_truth) {
  if (!config_.render_cameras) throw std::logic_error("CaptureRing: the simulator was configured without cameras");
  for (std::size_t i = 0; i < request.cameras.size(); ++i) {
    const int camera = request.cameras[i];
    if (camera < 0 || camera >= rig_.size() || (i > 0 && camera <= request.cameras[i - 1])) {
      throw std::invalid_argument("CaptureRing: the request's cameras must be rig indices, ascending, each once");
    }
  }
  World& world = *impl_->world;
  mj_forward(world.model(), world.data());  // kinematics at the current time
  const double exposed_at = world.data()->time;
  DrawCutFoliage();
  SetWeatherFor(exposed_at);
  const GroundTruth now = ground_truth();
  RingCapture capture;
  // The camera's clock is off the IMU's by the calibration's residual offset.
  capture.frame.stamp = exposed_at + config_.camera_time_offset;
  RingTruth& truth = capture.truth;
  if (with_ground_truth) truth.views.resize(static_cast<std::size_t>(rig_.size()));
  const bool moving = now.linear_velocity_base.norm() > 1e-4 || now.angular_velocity_base.norm() > 1e-4;
  for (int i : request.cameras) {
    const bool blur = config_.motion_blur && moving;
    RenderedView view = impl_->renderer->Render(i, request.resolution_scale, with_ground_truth, blur);
    auto start = std::chrono::steady_clock::now();
    // The sensor's exposure control, then the read-out: signal times exposure and gain, plus read
    // noise (amplified by the gain) seeded per frame and camera so each image is reproducible alone.
    const ExposureResult exposure = MeterExposure(view.rgb, parameters_.cameras.auto_exposure);
    impl_->timings.exposure_noise += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (blur) {
      start = std::chrono::steady_clock::now();
      const double exposure_time = parameters_.cameras.auto_exposure.daylight_exposure_time * exposure.exposure_factor;
      impl_->motion_blur.Apply(i * 100000 + view.rgb.cols, impl_->renderer->Model(i, request.resolution_scale),
                               view.depth, CameraTwistOf(now, rig_.camera(i).T_base_camera), exposure_time, &view.rgb);
      if (!with_ground_truth) view.depth.release();
      impl_->timings.motion_blur += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    start = std::chrono::steady_clock::now();
    const std::uint64_t image_seed =
        StreamSeed(config_.seed, "camera/" + std::to_string(impl_->frame) + "/" + std::to_string(i));
    impl_->read_noise->ReadOut(view.rgb, exposure.exposure_factor * exposure.gain,
                               parameters_.cameras.noise_sigma * exposure.gain, image_seed);
    messages::Image image;
    image.stamp = capture.frame.stamp;  // the camera's clock
    image.camera_index = i;
    image.width = view.rgb.cols;
    image.height = view.rgb.rows;
    image.encoding = "rgb8";
    image.data.assign(view.rgb.data, view.rgb.data + view.rgb.total() * view.rgb.elemSize());
    capture.frame.images.push_back(std::move(image));
    impl_->timings.exposure_noise += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (with_ground_truth) truth.views[static_cast<std::size_t>(i)] = std::move(view);
  }
  for (int i = 0; i < rig_.size(); ++i) {
    const int id = world.camera_id(i);
    Eigen::Isometry3d T_map_camera = PoseFromMujoco(world.data()->cam_xpos + 3 * id, world.data()->cam_xmat + 9 * id);
    T_map_camera.linear() =
        T_map_camera.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
    truth.T_map_camera.push_back(T_map_camera);
  }
  ++impl_->frame;
  ++impl_->timings.ring_frames;
  return capture;
}

GroundTruth Simulator::ground_truth() const {
  const World& world = *impl_->world;
  const mjModel* m = world.model();
  const mjData* d = world.data();
  GroundTruth truth;
  truth.stamp = d->time;
  // The free joint's qpos is the state at d->time (xpos lags by a step after mj_step).
  const int qpos = m->jnt_qposadr[m->body_jntadr[world.base_body()]];
  const int dof = m->jnt_dofadr[m->body_jntadr[world.base_body()]];
  truth.T_map_base.translation() << d->qpos[qpos], d->qpos[qpos + 1], d->qpos[qpos + 2];
  const Eigen::Quaterniond q(d->qpos[qpos + 3], d->qpos[qpos + 4], d->qpos[qpos + 5], d->qpos[qpos + 6]);
  truth.T_map_base.linear() = q.normalized().toRotationMatrix();
  // Free joint velocity: linear in the world frame, angular in the body frame.
  const Eigen::Vector3d linear_world(d->qvel[dof], d->qvel[dof + 1], d->qvel[dof + 2]);
  truth.linear_velocity_base = truth.T_map_base.linear().transpose() * linear_world;
  truth.angular_velocity_base << d->qvel[dof + 3], d->qvel[dof + 4], d->qvel[dof + 5];
  for (size_t i = 0; i < truth.arm_position.size(); ++i) truth.arm_position[i] = d->qpos[world.arm()[i].qpos];
  const int ee = impl_->end_effector_body;
  if (ee >= 0) truth.T_map_end_effector = PoseFromMujoco(d->xpos + 3 * ee, d->xmat + 9 * ee);
  truth.accelerometer_bias = impl_->imu->accelerometer_bias();
  truth.gyroscope_bias = impl_->imu->gyroscope_bias();
  return truth;
}

std::vector<ObstacleContact> Simulator::ObstacleContacts() const {
  const World& world = *impl_->world;
  const mjData* d = world.data();
  std::vector<ObstacleContact> contacts;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& contact = d->contact[i];
    for (const auto& [robot_geom, other] :
         {std::pair{contact.geom1, contact.geom2}, std::pair{contact.geom2, contact.geom1}}) {
      const GeomLabel* object = world.label(other);
      if (world.is_robot_geom(robot_geom) && object != nullptr && !object->is_ground &&
          object->object_class != garden::ObjectClass::kRobot) {
        contacts.push_back(
            {mj_id2name(world.model(), mjOBJ_GEOM, robot_geom), object->geom_name, object->object_class});
      }
    }
  }
  return contacts;
}

std::vector<ArmContact> Simulator::ArmContacts() const {
  const World& world = *impl_->world;
  const mjModel* m = world.model();
  const mjData* d = world.data();
  constexpr int kArmBit = 4;  // the arm_collision class's contype (robot_mjcf)
  std::vector<ArmContact> contacts;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& contact = d->contact[i];
    int arm = contact.geom1, other = contact.geom2;
    if (!(m->geom_contype[arm] & kArmBit)) std::swap(arm, other);
    if (!(m->geom_contype[arm] & kArmBit) || contact.dist > 0.0) continue;
    contacts.push_back({mj_id2name(m, mjOBJ_GEOM, arm), mj_id2name(m, mjOBJ_GEOM, other), -contact.dist});
  }
  return contacts;
}

cv::Mat Simulator::RenderExternalView(const Eigen::Vector3d& lookat, double distance, double azimuth, double elevation,
                                      int width, int height) {
  // A plant configured without cameras gets a renderer for views from outside (a trial's video).
  if (!impl_->renderer) impl_->renderer = std::make_unique<RingRenderer>(*impl_->world, rig_, config_.frustum_culling);
  // The view needs the kinematics of the state as it is (after PlaceRobot, say); the run must not
  // see that forward pass (it changes the data the next step starts from: with it, a trial with a
  // video drifted from the same trial without, measured on the navigation smoke), so the data is
  // put back as it was.
  const mjModel* m = impl_->world->model();
  mjData* d = impl_->world->data();
  // Put back however the view ends (a throw included).
  const auto put_back = [m, d](mjData* saved) {
    mj_copyData(d, m, saved);
    mj_deleteData(saved);
  };
  const std::unique_ptr<mjData, decltype(put_back)> saved(mj_copyData(nullptr, m, d), put_back);
  mj_forward(m, d);
  DrawCutFoliage();
  if (impl_->weather_time < 0.0 && impl_->clouds) SetWeatherFor(d->time);
  cv::Mat view = impl_->renderer->RenderExternalView(lookat, distance, azimuth, elevation, width, height);
  return view;
}

std::vector<CollisionHull> Simulator::GardenCollisionHulls() const {
  const World& world = *impl_->world;
  const mjModel* m = world.model();
  const mjData* d = world.data();
  std::vector<CollisionHull> hulls;
  for (int g = 0; g < m->ngeom; ++g) {
    const GeomLabel* label = world.label(g);
    if (label == nullptr || label->is_ground || label->object_class == garden::ObjectClass::kRobot) continue;
    if (m->geom_type[g] != mjGEOM_MESH || (m->geom_contype[g] == 0 && m->geom_conaffinity[g] == 0)) continue;
    const int mesh = m->geom_dataid[g];
    const int graph_address = m->mesh_graphadr[mesh];
    if (graph_address < 0) continue;  // MuJoCo made no hull: the mesh does not collide
    // mesh_graph: numvert, numface, vert_edgeadr[numvert], vert_globalid[numvert],
    // edge_localid[numvert + 3 numface], face_globalid[3 numface] (MuJoCo's convex hull).
    const int* graph = m->mesh_graph + graph_address;
    const int vertices = graph[0], faces = graph[1];
    const int* face_global = graph + 2 + 3 * vertices + 3 * faces;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() << d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1], d->geom_xpos[3 * g + 2];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) pose.linear()(r, c) = d->geom_xmat[9 * g + 3 * r + c];
    }
    CollisionHull hull;
    hull.geom = label->geom_name;
    hull.object_id = label->object_id;
    hull.object_class = label->object_class;
    // Only the hull's own vertices, the faces renumbered to them.
    const int* vertex_global = graph + 2 + vertices;
    const float* vertex = m->mesh_vert + 3 * m->mesh_vertadr[mesh];
    std::map<int, int> local;
    for (int v = 0; v < vertices; ++v) {
      const int id = vertex_global[v];
      local[id] = v;
      hull.vertices.push_back(pose * Eigen::Vector3d(vertex[3 * id], vertex[3 * id + 1], vertex[3 * id + 2]));
    }
    for (int f = 0; f < faces; ++f) {
      hull.triangles.push_back(
          {local.at(face_global[3 * f]), local.at(face_global[3 * f + 1]), local.at(face_global[3 * f + 2])});
    }
    hulls.push_back(std::move(hull));
  }
  return hulls;
}

void Simulator::PlaceRobot(const Pose2& pose) {
  World& world = *impl_->world;
  const mjModel* m = world.model();
  mjData* d = world.data();
  const int qpos = m->jnt_qposadr[m->body_jntadr[world.base_body()]];
  const int dof = m->jnt_dofadr[m->body_jntadr[world.base_body()]];
  d->qpos[qpos] = pose.x;
  d->qpos[qpos + 1] = pose.y;
  d->qpos[qpos + 3] = std::cos(0.5 * pose.yaw);
  d->qpos[qpos + 4] = 0.0;
  d->qpos[qpos + 5] = 0.0;
  d->qpos[qpos + 6] = std::sin(0.5 * pose.yaw);
  for (int i = 0; i < 6; ++i) d->qvel[dof + i] = 0.0;
  mj_forward(m, d);
}

}  // namespace trimbot::sim
