#pragma once
// The simulated robot in its garden, as one system with explicit inputs, outputs and state:
//   inputs   base velocity command, arm command, cutter command
//   outputs  SensorOutputs - the sensor messages the robot's drivers deliver (what the stack sees)
//            GroundTruth   - the true state, contacts and the renderer's depth and labels; it goes
//                            to the evaluation only, never to the stack
//   state    MuJoCo state + sensor-model state.
// Time advances in fixed physics steps; every sensor runs at an integer number of steps, and all
// noise comes from streams seeded by `seed`, so a run is reproduced exactly by its seed. This
// header shows no MuJoCo or OpenGL: those stay inside sim/.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/garden/conditions.h"
#include "trimbot/garden/foliage.h"
#include "trimbot/garden/garden.h"
#include "trimbot/messages/commands.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/robot/robot_parameters.h"
#include "trimbot/sim/faults.h"
#include "trimbot/sim/rendered_view.h"
#include "trimbot/sim/world_builder.h"

namespace trimbot::sim {

class World;

struct SimulatorConfig {
  robot::RobotFiles robot;  // urdf, camchain (the cameras as they really are), parameters
  garden::Garden garden;    // as built (read once by the caller); its source names it in errors
  // Objects placed in the world beyond the garden file's (a scenario's obstacles the survey never
  // saw); their ids must not be the garden's.
  std::vector<garden::GardenObject> extra_objects;
  std::string world_dir;  // where world.xml and its textures are written
  std::uint64_t seed = 0;
  garden::Conditions conditions;  // time of day, shadows, growth
  Pose2 start;
  double timestep = 0.0025;  // s
  bool render_cameras = true;
  bool cameras_on_schedule = true;    // false: the ring renders only when CaptureRing is called
  int ground_truth_every_frames = 0;  // depth and label images with every n-th ring frame (0: none)
  double resolution_scale = 1.0;      // 0.5 renders half-resolution images
  int msaa_samples = 4;               // anti-aliasing; 0 halves the render time, edges get jagged
  bool frustum_culling = true;        // each camera draws only the geoms that can show in it (same image)
  double imu_noise_scale = 1.0;       // multiplies every IMU noise parameter
  double wheel_slip_scale = 1.0;      // multiplies the surfaces' slip (mean and spread)
  // Motion blur: each image integrates the rig's motion over its exposure time (the auto
  // exposure's, robot::AutoExposure). Wind and clouds are the conditions' (garden::Conditions).
  bool motion_blur = true;
  // The cameras' clock against the IMU's (s): images are stamped this much later than they were
  // exposed (what a camera-IMU calibration leaves; the stack assumes 0).
  double camera_time_offset = 0.0;
  std::vector<Fault> faults;  // injected at their times
  // Topiaries (object ids) whose foliage the spinning cutter cuts: ground truth garden::Foliage,
  // drawn as it is cut; their leaves give way and their wood collides (WorldOptions).
  std::vector<int> cuttable_objects;
};

// What the robot's drivers deliver in one physics step.
struct SensorOutputs {
  std::vector<messages::ImuSample> imu;
  std::vector<messages::WheelTicks> wheel_ticks;
  std::vector<messages::ArmJointState> arm_joints;
  std::optional<messages::RingFrame> ring;  // noisy images, when the ring was rendered this step
  void Clear() {
    imu.clear();
    wheel_ticks.clear();
    arm_joints.clear();
    ring.reset();
  }
};

// A contact between the robot and a garden object other than the ground.
struct ObstacleContact {
  std::string robot_geom;
  std::string object_geom;
  garden::ObjectClass object_class = garden::ObjectClass::kNone;
};

// A contact of an arm link or the cutter with anything: the robot itself, the ground, the garden.
struct ArmContact {
  std::string arm_geom;
  std::string other_geom;
  double penetration = 0.0;  // m
};

// The convex hull MuJoCo collides with for one garden geom, in the world frame.
struct CollisionHull {
  std::string geom;
  int object_id = 0;
  garden::ObjectClass object_class = garden::ObjectClass::kNone;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// The renderer's truth about one ring frame.
struct RingTruth {
  std::vector<RenderedView> views;              // depth/labels on ground-truth frames, else empty
  std::vector<Eigen::Isometry3d> T_map_camera;  // true optical-frame poses
};

// Ground truth at the current time, in the map frame (MuJoCo's world frame).
struct GroundTruth {
  double stamp = 0.0;
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  Eigen::Vector3d linear_velocity_base = Eigen::Vector3d::Zero();   // in base_link
  Eigen::Vector3d angular_velocity_base = Eigen::Vector3d::Zero();  // in base_link
  std::array<double, messages::kArmJoints> arm_position{};
  Eigen::Isometry3d T_map_end_effector = Eigen::Isometry3d::Identity();
  Eigen::Vector3d accelerometer_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyroscope_bias = Eigen::Vector3d::Zero();
  // The ring's cameras were triggered in this step and deliver images (no dropout), whether or
  // not they were rendered: what an image-driven source (or its simulated stand-in) works from.
  bool ring_exposed = false;
  std::optional<RingTruth> ring;          // with SensorOutputs::ring
  std::vector<ObstacleContact> contacts;  // robot against garden objects, now
  std::vector<ArmContact> arm_contacts;   // the arm against anything, now
};

// Wall-clock seconds the simulator spent per stage since it was made (not part of any result:
// for the run's timing report).
struct SimulatorTimings {
  double physics = 0.0;          // actuation, MuJoCo step, IMU / encoder models, contacts
  double render_draw = 0.0;      // OpenGL drawing of the camera images
  double render_readback = 0.0;  // pixels back from OpenGL
  double distortion = 0.0;       // pinhole render -> calibrated radtan camera (precomputed remap)
  double exposure_noise = 0.0;   // auto exposure and read noise
  double depth = 0.0;            // depth images (for ground truth and motion blur)
  double ground_truth = 0.0;     // label images, when asked for
  double motion_blur = 0.0;      // blurring the images by the rig's motion
  double wind = 0.0;             // moving the plants' meshes for a frame
  double RenderSeconds() const {
    return render_draw + render_readback + distortion + exposure_noise + depth + ground_truth + motion_blur + wind;
  }
  long physics_steps = 0;
  long ring_frames = 0;
  long camera_images = 0;
  long geoms_drawn = 0;   // summed over camera images: geoms in each camera's view volume
  long geoms_culled = 0;  // and those outside it, not drawn
};

struct RingCapture {
  messages::RingFrame frame;  // sensor output (noisy images)
  RingTruth truth;
};

class Simulator {
 public:
  explicit Simulator(const SimulatorConfig& config);
  ~Simulator();

  // Inputs.
  void SetBaseCommand(const messages::BaseVelocityCommand& command);
  void SetArmCommand(const messages::ArmCommand& command);
  void SetCutterCommand(const messages::CutterCommand& command);
  void Apply(const messages::RobotCommands& commands);

  // One physics step: the sensor messages due in it are appended to `sensors`; `truth` is set to
  // the ground truth after the step.
  void Step(SensorOutputs* sensors, GroundTruth* truth);
  double time() const;
  double timestep() const { return config_.timestep; }

  // Ground truth now (without a ring frame).
  GroundTruth ground_truth() const;

  const robot::RobotDescription& robot() const { return robot_; }
  const robot::CameraRig& rig() const { return rig_; }
  const robot::RobotParameters& parameters() const { return parameters_; }
  const garden::Garden& garden() const { return garden_; }
  const WorldSpec& world_spec() const { return spec_; }
  // Renders the cameras now (outside the camera schedule): all of them at the configured
  // resolution, or those `request` names at its resolution (the frame then holds only those
  // images; RingTruth's views of the others are empty).
  RingCapture CaptureRing(bool with_ground_truth);
  RingCapture CaptureRing(const messages::RingRequest& request, bool with_ground_truth);
  // Puts the robot at `pose` on the ground (same height as now), at rest: for data sets of views,
  // not for runs (the sensors' state is not reset).
  void PlaceRobot(const Pose2& pose);
  // A view of the world now from outside the robot (RingRenderer::RenderExternalView).
  cv::Mat RenderExternalView(const Eigen::Vector3d& lookat, double distance, double azimuth, double elevation,
                             int width, int height);
  // The foliage of a cuttable topiary as cut so far (ground truth); nullptr for another object.
  const garden::Foliage* foliage(int object_id) const;
  // What MuJoCo collides with for each garden object (meshes: their convex hulls), in the world frame.
  std::vector<CollisionHull> GardenCollisionHulls() const;
  // Every camera at the configured resolution (what the camera schedule renders).
  messages::RingRequest WholeRing() const;
  // Where the wall-clock time went since the start.
  SimulatorTimings timings() const;
  // The MuJoCo world, for tests that compare it with the URDF (include trimbot/sim/world.h).
  World& world();

 private:
  const garden::SlipModel* SurfaceUnder(int wheel_geom) const;
  // Applies the faults due at the current time; returns whether the cameras deliver images.
  bool ApplyFaults();
  // The weather the cameras see: plants moved by the wind, the sun dimmed by clouds.
  void SetUpWeather();
  void SetWeatherFor(double t);
  // The cuttable topiaries: their foliage and drawn meshes.
  void SetUpFoliage();
  // The blade's sweep since the last step cuts the foliage (while the cutter spins).
  void CutFoliage(const GroundTruth& truth);
  // The drawn meshes of foliage cut since they were last drawn, as it is now.
  void DrawCutFoliage();
  std::vector<ObstacleContact> ObstacleContacts() const;
  std::vector<ArmContact> ArmContacts() const;
  void ReadSensors(double stamp_before, SensorOutputs* sensors);

  SimulatorConfig config_;
  robot::RobotDescription robot_;
  robot::RobotParameters parameters_;
  robot::CameraRig rig_;
  garden::Garden garden_;
  WorldSpec spec_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace trimbot::sim
