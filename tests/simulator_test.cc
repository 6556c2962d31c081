// The simulated robot in MuJoCo: drive kinematics against the analytic arc, IMU in the world,
// the MuJoCo model against the URDF, contacts with garden objects.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "sim_test_support.h"
#include "trimbot/sim/base_controller.h"
#include "trimbot/sim/world.h"

namespace trimbot::sim {
namespace {

using testing::TestConfig;
using testing::TestLawn;

struct PlanarPose {
  double x = 0, y = 0, yaw = 0;
};

PlanarPose Planar(const Eigen::Isometry3d& pose) {
  return {pose.translation().x(), pose.translation().y(), std::atan2(pose.linear()(1, 0), pose.linear()(0, 0))};
}

// Drives a constant command and integrates the unicycle model with the same rate-limited
// velocities the base controller produces (exact arc per step).
void DriveAndCompareWithArc(double linear, double angular, double seconds, double tolerance) {
  SimulatorConfig config = TestConfig(TestLawn(), "arc");
  config.start = {0.0, -1.0, 0.3};
  Simulator simulator(config);
  BaseController reference(simulator.robot().drive(), simulator.parameters().drive);
  simulator.SetBaseCommand({linear, angular});
  reference.SetCommand({linear, angular});
  PlanarPose expected = {config.start.x, config.start.y, config.start.yaw};
  SensorOutputs outputs;
  GroundTruth truth_now;
  double worst = 0.0, worst_heading = 0.0;
  while (simulator.time() < seconds) {
    outputs.Clear();
    simulator.Step(&outputs, &truth_now);
    reference.Update(simulator.timestep());
    const double v = reference.linear(), w = reference.angular(), dt = simulator.timestep();
    if (std::abs(w) > 1e-9) {
      expected.x += v / w * (std::sin(expected.yaw + w * dt) - std::sin(expected.yaw));
      expected.y -= v / w * (std::cos(expected.yaw + w * dt) - std::cos(expected.yaw));
    } else {
      expected.x += v * dt * std::cos(expected.yaw);
      expected.y += v * dt * std::sin(expected.yaw);
    }
    expected.yaw += w * dt;
    const PlanarPose actual = Planar(simulator.ground_truth().T_map_base);
    worst = std::max(worst, std::hypot(actual.x - expected.x, actual.y - expected.y));
    worst_heading = std::max(worst_heading, std::abs(std::remainder(actual.yaw - expected.yaw, 2 * M_PI)));
  }
  const PlanarPose end = Planar(simulator.ground_truth().T_map_base);
  EXPECT_LT(worst, tolerance) << "end at " << end.x << ", " << end.y << " expected " << expected.x << ", "
                              << expected.y;
  EXPECT_LT(worst_heading, 0.02);
  // The robot stays on the ground and upright.
  EXPECT_NEAR(simulator.ground_truth().T_map_base.translation().z(), 0.0, 0.01);
  EXPECT_GT(simulator.ground_truth().T_map_base.linear()(2, 2), 0.999);
}

TEST(BaseKinematics, StraightDriveFollowsTheCommand) { DriveAndCompareWithArc(0.25, 0.0, 12.0, 0.02); }

TEST(BaseKinematics, ArcFollowsTheAnalyticCircle) {
  // A quarter turn and more at 25 cm/s on a 1.25 m radius.
  DriveAndCompareWithArc(0.25, 0.2, 12.0, 0.03);
}

TEST(BaseKinematics, TurnOnTheSpot) { DriveAndCompareWithArc(0.0, 0.5, 6.0, 0.02); }

TEST(SimulatedImu, ReadsGravityAtRestAndTheYawRateInATurn) {
  Simulator simulator(TestConfig(TestLawn(), "imu"));
  SensorOutputs outputs;
  GroundTruth truth_now;
  std::vector<messages::ImuSample> samples;
  while (simulator.time() < 3.0) {
    simulator.Step(&outputs, &truth_now);
  }
  // Discard the first second (the robot settles on its wheels).
  for (const auto& s : outputs.imu) {
    if (s.stamp > 1.0) samples.push_back(s);
  }
  ASSERT_GT(samples.size(), 350u);  // 200 Hz
  Eigen::Vector3d mean_a = Eigen::Vector3d::Zero(), mean_g = Eigen::Vector3d::Zero();
  for (const auto& s : samples) {
    mean_a += s.linear_acceleration / samples.size();
    mean_g += s.angular_velocity / samples.size();
  }
  const GroundTruth truth = simulator.ground_truth();
  EXPECT_LT((mean_a - truth.accelerometer_bias - Eigen::Vector3d(0, 0, 9.81)).norm(), 0.02);
  EXPECT_LT((mean_g - truth.gyroscope_bias).norm(), 0.002);

  outputs.Clear();
  simulator.SetBaseCommand({0.0, 0.4});
  while (simulator.time() < 8.0) simulator.Step(&outputs, &truth_now);
  double yaw_rate = 0.0;
  int n = 0;
  for (const auto& s : outputs.imu) {
    if (s.stamp > 6.0) {
      yaw_rate += s.angular_velocity.z() - simulator.ground_truth().gyroscope_bias.z();
      ++n;
    }
  }
  EXPECT_NEAR(yaw_rate / n, 0.4, 0.01);
}

TEST(WheelEncoders, OdometryOnGrassOverestimatesByTheSlip) {
  SimulatorConfig config = TestConfig(TestLawn(), "slip");
  config.start = {-4.0, -1.0, 0.0};
  Simulator simulator(config);
  simulator.SetBaseCommand({0.25, 0.0});
  SensorOutputs outputs;
  GroundTruth truth_now;
  while (simulator.time() < 20.0) simulator.Step(&outputs, &truth_now);
  ASSERT_GE(outputs.wheel_ticks.size(), 999u);  // 50 Hz
  const auto& first = outputs.wheel_ticks.front();
  const auto& last = outputs.wheel_ticks.back();
  const double radians_per_tick = 2 * M_PI / simulator.parameters().wheel_encoders.ticks_per_revolution;
  const double measured = simulator.robot().drive().LinearFromWheels(
      {(last.left - first.left) * radians_per_tick, (last.right - first.right) * radians_per_tick});
  const double travelled = simulator.ground_truth().T_map_base.translation().x() - config.start.x;
  EXPECT_GT(travelled, 4.5);
  // Grass slip: 3% on average; over 20 s the Gauss-Markov part (2 s correlation) averages down.
  EXPECT_NEAR(measured / travelled - 1.0, garden::PropertiesOf(garden::Surface::kGrass).slip.mean, 0.012);
}

TEST(MujocoModel, AgreesWithTheUrdf) {
  SimulatorConfig config = TestConfig(TestLawn(), "agree");
  config.start = {1.0, 2.0, 0.7};
  Simulator simulator(config);
  World& world = simulator.world();
  const mjModel* m = world.model();
  mjData* d = world.data();
  // Compare at the zero joint configuration (the arm starts at home: reset it first).
  for (const auto& joint : world.arm()) d->qpos[joint.qpos] = 0.0;
  mj_forward(m, d);
  const Eigen::Isometry3d T_map_base = simulator.ground_truth().T_map_base;
  const auto& urdf = simulator.robot().urdf();
  int bodies = 0, joints = 0;
  for (const auto& [name, link] : urdf.links_) {
    const int body = mj_name2id(m, mjOBJ_BODY, name.c_str());
    const int site = mj_name2id(m, mjOBJ_SITE, name.c_str());
    if (name.find("_optical_frame") != std::string::npos) continue;  // cameras, checked below
    ASSERT_TRUE(body >= 0 || site >= 0) << "link " << name << " has no MuJoCo body or site";
    const mjtNum* pos = body >= 0 ? d->xpos + 3 * body : d->site_xpos + 3 * site;
    const mjtNum* mat = body >= 0 ? d->xmat + 9 * body : d->site_xmat + 9 * site;
    const Eigen::Isometry3d expected = T_map_base * simulator.robot().FramePose(name);
    Eigen::Matrix3d rotation;
    rotation << mat[0], mat[1], mat[2], mat[3], mat[4], mat[5], mat[6], mat[7], mat[8];
    EXPECT_LT((Eigen::Vector3d(pos[0], pos[1], pos[2]) - expected.translation()).norm(), 1e-6) << name;
    EXPECT_LT(Eigen::AngleAxisd(rotation.transpose() * expected.linear()).angle(), 1e-6) << name;
    bodies += body >= 0;
  }
  for (const auto& [name, joint] : urdf.joints_) {
    if (joint->type == urdf::Joint::FIXED) continue;
    const int id = mj_name2id(m, mjOBJ_JOINT, name.c_str());
    ASSERT_GE(id, 0) << "joint " << name;
    EXPECT_EQ(m->jnt_type[id], mjJNT_HINGE) << name;
    // The joint axis in the world matches the URDF axis carried by the child frame.
    const Eigen::Isometry3d child = T_map_base * simulator.robot().FramePose(joint->child_link_name);
    const Eigen::Vector3d axis = child.linear() * Eigen::Vector3d(joint->axis.x, joint->axis.y, joint->axis.z);
    EXPECT_LT((Eigen::Vector3d(d->xaxis[3 * id], d->xaxis[3 * id + 1], d->xaxis[3 * id + 2]) - axis).norm(), 1e-6)
        << name;
    if (joint->type == urdf::Joint::REVOLUTE) {
      EXPECT_NEAR(m->jnt_range[2 * id], joint->limits->lower, 1e-9) << name;
      EXPECT_NEAR(m->jnt_range[2 * id + 1], joint->limits->upper, 1e-9) << name;
    }
    ++joints;
  }
  EXPECT_EQ(joints, 9);  // 2 wheels, 6 arm joints, cutter
  EXPECT_GE(bodies, 11);
  // Cameras: MuJoCo camera i sits at the calibrated optical frame (looking along -z, y up).
  for (int i = 0; i < simulator.rig().size(); ++i) {
    const int id = world.camera_id(i);
    const Eigen::Isometry3d expected = T_map_base * simulator.robot().FramePose(robot::RobotFrames::CameraOptical(i));
    const Eigen::Vector3d position(d->cam_xpos[3 * id], d->cam_xpos[3 * id + 1], d->cam_xpos[3 * id + 2]);
    const Eigen::Vector3d looking(-d->cam_xmat[9 * id + 2], -d->cam_xmat[9 * id + 5], -d->cam_xmat[9 * id + 8]);
    const Eigen::Vector3d down(-d->cam_xmat[9 * id + 1], -d->cam_xmat[9 * id + 4], -d->cam_xmat[9 * id + 7]);
    EXPECT_LT((position - expected.translation()).norm(), 1e-6) << "cam" << i;
    EXPECT_LT((looking - expected.linear().col(2)).norm(), 1e-6) << "cam" << i;
    EXPECT_LT((down - expected.linear().col(1)).norm(), 1e-6) << "cam" << i;
  }
  // Total mass from the URDF inertials.
  double urdf_mass = 0.0;
  for (const auto& [name, link] : urdf.links_) urdf_mass += link->inertial ? link->inertial->mass : 0.0;
  double mujoco_mass = 0.0;
  for (int b = 1; b < m->nbody; ++b) mujoco_mass += m->body_mass[b];
  EXPECT_NEAR(mujoco_mass, urdf_mass, 1e-6);
}

TEST(Arm, ServosReachAPositionTargetAgainstGravity) {
  Simulator simulator(TestConfig(TestLawn(), "arm"));
  messages::ArmCommand command;
  command.position = {0.5, 2.4, 1.2, 4.2, 1.44, 1.32};
  simulator.SetArmCommand(command);
  SensorOutputs outputs;
  GroundTruth truth_now;
  while (simulator.time() < 4.0) {
    outputs.Clear();
    simulator.Step(&outputs, &truth_now);
  }
  const GroundTruth truth = simulator.ground_truth();
  for (size_t i = 0; i < command.position.size(); ++i) {
    EXPECT_NEAR(truth.arm_position[i], command.position[i], 0.01) << "arm_joint_" << i + 1;
  }
  // The end effector is where the URDF puts it for these joint angles.
  std::map<std::string, double> joints;
  for (size_t i = 0; i < command.position.size(); ++i)
    joints[robot::RobotFrames::ArmJoint(static_cast<int>(i))] = truth.arm_position[i];
  const Eigen::Vector3d expected =
      (truth.T_map_base * simulator.robot().FramePose("arm_end_effector", joints)).translation();
  EXPECT_LT((truth.T_map_end_effector.translation() - expected).norm(), 0.01);
}

// A topiary placed where the blade ends a move (3 cm outside its target, in the leaves grown at
// 0.35): with the cutter spinning the simulator's foliage is the grown foliage cut by the true blade
// disc step by step, exactly; with it off nothing is cut.
garden::Foliage SweepThroughATopiary(bool cutter_on, long* blade_cuts) {
  const messages::ArmCommand reach = [] {
    messages::ArmCommand c;
    c.position = {0.5, 2.4, 1.2, 4.2, 1.44, 1.32};
    return c;
  }();
  SimulatorConfig config = TestConfig(TestLawn(), cutter_on ? "cut_on" : "cut_off");
  config.conditions.growth = 0.35;
  config.cuttable_objects = {1};
  const robot::RobotDescription robot = robot::RobotDescription::Load(config.robot.urdf);
  std::map<std::string, double> joints;
  for (size_t i = 0; i < reach.position.size(); ++i)
    joints[robot::RobotFrames::ArmJoint(static_cast<int>(i))] = reach.position[i];
  const Eigen::Vector3d blade = robot.FramePose("cutter_blade_link", joints).translation();  // start: map = base
  garden::GardenObject& bush = *std::find_if(config.garden.objects.begin(), config.garden.objects.end(),
                                             [](const garden::GardenObject& o) { return o.id == 1; });
  const Eigen::Vector3d out = Eigen::Vector3d(blade.x(), blade.y(), 0.0).normalized();
  const garden::Superellipsoid target = garden::TargetShape(bush);
  const Eigen::Vector3d centre = blade + out * (target.Radius(-out) + 0.03);
  bush.position = centre.head<2>();
  bush.base_height = centre.z() - target.half.z();
  Simulator simulator(config);
  garden::Foliage offline = *simulator.foliage(1);
  simulator.SetArmCommand(reach);
  simulator.SetCutterCommand({cutter_on});
  SensorOutputs outputs;
  GroundTruth truth;
  const auto disc = [&](const GroundTruth& t) {
    const Eigen::Isometry3d T_map_blade = t.T_map_end_effector * robot.BladeInCutter();
    return garden::BladeDisc{T_map_blade.translation(), T_map_blade.linear().col(2), robot.BladeRadius()};
  };
  garden::BladeDisc last = disc(simulator.ground_truth());
  while (simulator.time() < 4.0) {
    outputs.Clear();
    simulator.Step(&outputs, &truth);
    if (cutter_on) offline.Cut(last, disc(truth));
    last = disc(truth);
  }
  *blade_cuts = offline.cut_columns();
  EXPECT_EQ(simulator.foliage(2), nullptr) << "only the trimmed bush is cuttable";
  int differing = 0;
  for (int i = 0; i < offline.columns(); ++i) differing += simulator.foliage(1)->height(i) != offline.height(i);
  EXPECT_EQ(differing, 0) << "columns the simulator cut otherwise than the blade's sweep";
  return *simulator.foliage(1);
}

TEST(Foliage, TheSpinningBladeCutsWhatItSweepsInTheSimulator) {
  long cuts_on = 0, cuts_off = 0;
  const garden::Foliage cut = SweepThroughATopiary(true, &cuts_on);
  const garden::Foliage uncut = SweepThroughATopiary(false, &cuts_off);
  EXPECT_GT(cuts_on, 100) << "the blade went through the leaves";
  EXPECT_EQ(uncut.cut_columns(), 0) << "the cutter was off";
  EXPECT_LT(cut.Measure().overgrowth_volume, uncut.Measure().overgrowth_volume);
}

TEST(Contacts, DrivingIntoTheHedgeIsReported) {
  SimulatorConfig config = TestConfig(TestLawn(), "hedge");
  config.start = {6.8, 0.0, 0.0};  // hedge face at x = 8.2, the chassis front 0.58 m ahead
  Simulator simulator(config);
  simulator.SetBaseCommand({0.3, 0.0});
  SensorOutputs outputs;
  GroundTruth truth_now;
  std::vector<ObstacleContact> contacts;
  while (simulator.time() < 8.0 && contacts.empty()) {
    outputs.Clear();
    simulator.Step(&outputs, &truth_now);
    contacts = truth_now.contacts;
  }
  ASSERT_FALSE(contacts.empty());
  EXPECT_EQ(contacts.front().object_class, garden::ObjectClass::kHedge);
  EXPECT_NEAR(simulator.ground_truth().T_map_base.translation().x(), 8.2 - 0.58, 0.05);
}

}  // namespace
}  // namespace trimbot::sim

namespace trimbot::sim {
namespace {

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The garden looks the same in every run: its textures and foliage come from the garden's own
// seed, the run's seed only from sensor noise, faults and dynamics.
TEST(World, TheGardensLookDoesNotDependOnTheRunSeed) {
  SimulatorConfig a = TestConfig(TestLawn(), "look_a"), b = TestConfig(TestLawn(), "look_b");
  a.seed = 1;
  b.seed = 2;
  // From empty folders: a texture left by an earlier build must not stand in for a missing one.
  std::filesystem::remove_all(a.world_dir);
  std::filesystem::remove_all(b.world_dir);
  { Simulator first(a); }
  { Simulator second(b); }
  for (const char* texture : {"grass_v0.png", "grass_v3.png", "foliage.png", "bark.png"}) {
    const std::string bytes = FileBytes(a.world_dir + "/textures/" + texture);
    EXPECT_FALSE(bytes.empty()) << texture;
    EXPECT_EQ(bytes, FileBytes(b.world_dir + "/textures/" + texture)) << texture;
  }
  // The same foliage meshes (inline in world.xml), once the folder names are the same.
  std::string world_b = FileBytes(b.world_dir + "/world.xml");
  for (std::size_t at = world_b.find("look_b"); at != std::string::npos; at = world_b.find("look_b", at)) {
    world_b.replace(at, 6, "look_a");
  }
  EXPECT_EQ(FileBytes(a.world_dir + "/world.xml"), world_b);
  const garden::Garden lawn = garden::Garden::Load(TestLawn());
  EXPECT_EQ(lawn.appearance_seed, garden::Garden::Load(TestLawn()).appearance_seed);
  EXPECT_NE(lawn.appearance_seed,
            garden::Garden::Load(testing::SourcePath("garden_scenes/gardens/wageningen.yaml")).appearance_seed);
}

}  // namespace
}  // namespace trimbot::sim

namespace trimbot::sim {
namespace {

std::string NominalRobotMjcfPath() { return testing::SourcePath("robot/") + kRobotMjcfFile; }

// The robot's MJCF is a model of its own: robot/mjcf/trimbot.xml compiles without the garden and
// holds what the simulator drives and reads (the URDF's joints, the ring's cameras, the actuators,
// the IMU's sensors).
TEST(RobotMjcf, LoadsOnItsOwn) {
  char error[1024] = "";
  mjModel* m = mj_loadXML(NominalRobotMjcfPath().c_str(), nullptr, error, sizeof error);
  ASSERT_NE(m, nullptr) << error;
  const robot::RobotDescription robot = robot::RobotDescription::Load(testing::SourcePath("robot/urdf/trimbot.urdf"));
  // The robot alone: no garden (meshes, textures, lights) and nothing in the world body.
  EXPECT_EQ(m->nmesh, 0);
  EXPECT_EQ(m->ntex, 0);
  EXPECT_EQ(m->nlight, 0);
  for (int g = 0; g < m->ngeom; ++g) EXPECT_GT(m->geom_bodyid[g], 0) << mj_id2name(m, mjOBJ_GEOM, g);
  EXPECT_STREQ(mj_id2name(m, mjOBJ_BODY, 1), robot::RobotFrames::kBase);
  EXPECT_EQ(m->jnt_type[m->body_jntadr[1]], mjJNT_FREE);
  // Every moving URDF joint, a hinge.
  int hinges = 0;
  for (const auto& [name, joint] : robot.urdf().joints_) {
    if (joint->type == urdf::Joint::FIXED) continue;
    const int id = mj_name2id(m, mjOBJ_JOINT, name.c_str());
    ASSERT_GE(id, 0) << name;
    EXPECT_EQ(m->jnt_type[id], mjJNT_HINGE) << name;
    ++hinges;
  }
  EXPECT_EQ(hinges, 9);
  EXPECT_EQ(m->njnt, 1 + hinges);
  // The actuators: the wheels' motors, the arm's servos, the cutter's motor, each on its joint.
  std::vector<std::pair<std::string, std::string>> actuators = {
      {"left_wheel_joint_motor", robot::RobotFrames::kLeftWheelJoint},
      {"right_wheel_joint_motor", robot::RobotFrames::kRightWheelJoint}};
  for (const auto& joint : robot.ArmJointNames()) actuators.push_back({joint + "_servo", joint});
  actuators.push_back({"cutter_motor", robot::RobotFrames::kCutterJoint});
  ASSERT_EQ(actuators.size(), 2u + messages::kArmJoints + 1u);
  EXPECT_EQ(m->nu, static_cast<int>(actuators.size()));
  for (const auto& [actuator, joint] : actuators) {
    const int id = mj_name2id(m, mjOBJ_ACTUATOR, actuator.c_str());
    ASSERT_GE(id, 0) << actuator;
    EXPECT_EQ(m->actuator_trnid[2 * id], mj_name2id(m, mjOBJ_JOINT, joint.c_str())) << actuator;
  }
  // The ring's ten cameras on camera_ring_link, cam0 ... cam9 in the rig's order.
  ASSERT_EQ(m->ncam, 10);
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(mj_name2id(m, mjOBJ_CAMERA, ("cam" + std::to_string(i)).c_str()), i);
    EXPECT_STREQ(mj_id2name(m, mjOBJ_BODY, m->cam_bodyid[i]), robot::RobotFrames::kCameraRing);
  }
  // The IMU: accelerometer and gyro at imu_link.
  const int site = mj_name2id(m, mjOBJ_SITE, robot::RobotFrames::kImu);
  ASSERT_GE(site, 0);
  EXPECT_EQ(m->nsensor, 2);
  for (const auto& [sensor, type] :
       {std::pair{"imu_accelerometer", mjSENS_ACCELEROMETER}, std::pair{"imu_gyro", mjSENS_GYRO}}) {
    const int id = mj_name2id(m, mjOBJ_SENSOR, sensor);
    ASSERT_GE(id, 0) << sensor;
    EXPECT_EQ(m->sensor_type[id], type) << sensor;
    EXPECT_EQ(m->sensor_objid[id], site) << sensor;
  }
  // It simulates: a second of free fall with the arm held.
  mjData* d = mj_makeData(m);
  while (d->time < 1.0) mj_step(m, d);
  EXPECT_NEAR(d->qpos[2], -0.5 * 9.81, 0.05);
  for (int w = 0; w < mjNWARNING; ++w) EXPECT_EQ(d->warning[w].number, 0) << "MuJoCo warning " << w;
  mj_deleteData(d);
  mj_deleteModel(m);
}

// The checked-in file cannot go stale: it is what the URDF and the nominal calibration give
// (after a change, trimbot_robot_mjcf robot/ rewrites it).
TEST(RobotMjcf, IsWhatTheUrdfAndTheNominalCalibrationGive) {
  std::istringstream file(testing::ReadText(NominalRobotMjcfPath())),
      expected(NominalRobotMjcf(testing::SourcePath("robot")));
  std::string file_line, expected_line;
  for (int line = 1; std::getline(expected, expected_line); ++line) {
    ASSERT_TRUE(std::getline(file, file_line) && file_line == expected_line)
        << "robot/mjcf/trimbot.xml is out of date (run trimbot_robot_mjcf robot/): line " << line << " should be\n"
        << expected_line;
  }
  EXPECT_FALSE(std::getline(file, file_line)) << "robot/mjcf/trimbot.xml goes on after its end: " << file_line;
}

// A run's world includes its robot (robot.xml beside world.xml: the run's start pose and
// calibration) and adds the garden only.
TEST(RobotMjcf, TheWorldIncludesTheRunsRobot) {
  SimulatorConfig config = TestConfig(TestLawn(), "robot_mjcf");
  config.start = {1.0, -2.0, 0.4};
  Simulator simulator(config);
  const std::string robot_xml = testing::ReadText(config.world_dir + "/robot.xml");
  EXPECT_EQ(robot_xml, ComposeRobot(simulator.robot(), simulator.rig(), {config.start}).xml);
  const std::string world_xml = testing::ReadText(config.world_dir + "/world.xml");
  EXPECT_NE(world_xml.find("<include file=\"robot.xml\"/>"), std::string::npos);
  for (const char* robot_part : {"<body", "<actuator", "<sensor", "<camera", "class=\"robot\""}) {
    EXPECT_EQ(world_xml.find(robot_part), std::string::npos) << robot_part;
  }
  char error[1024] = "";
  mjModel* robot = mj_loadXML((config.world_dir + "/robot.xml").c_str(), nullptr, error, sizeof error);
  ASSERT_NE(robot, nullptr) << error;
  const mjModel* world = simulator.world().model();
  EXPECT_EQ(world->nbody, robot->nbody);
  EXPECT_EQ(world->nq, robot->nq);
  EXPECT_EQ(world->nu, robot->nu);
  EXPECT_EQ(world->nsensor, robot->nsensor);
  EXPECT_EQ(world->ncam, robot->ncam);
  for (int i = 0; i < 7; ++i) EXPECT_EQ(world->qpos0[i], robot->qpos0[i]) << i;  // the start pose
  mj_deleteModel(robot);
}

}  // namespace
}  // namespace trimbot::sim
