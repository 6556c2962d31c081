#pragma once
// The robot's MJCF: a MuJoCo model of the robot alone - its default classes, the URDF's links as
// bodies (joints, geoms, sites), the ring's cameras at their calibrated poses, the actuators and
// the IMU's sensors - as a complete <mujoco> document that MuJoCo's viewer opens on its own.
// robot/mjcf/trimbot.xml is this model for the nominal robot (NominalRobotMjcf); each run writes
// its own, at its start pose and with its calibration, as robot.xml beside its world.xml, which
// includes it (world_builder).
#include <cstdint>
#include <string>
#include <vector>

#include "trimbot/common/pose2.h"
#include "trimbot/garden/object_class.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_description.h"

namespace trimbot::sim {

// What the label images report for a geom.
struct GeomLabel {
  std::string geom_name;
  garden::ObjectClass object_class = garden::ObjectClass::kNone;
  std::uint16_t object_id = 0;
  bool is_ground = false;
  garden::Surface surface = garden::Surface::kGrass;  // meaningful when is_ground
};

struct RobotMjcfOptions {
  Pose2 start;                       // base_link in the world (the free joint's initial pose)
  double render_oversampling = 1.0;  // the cameras' field of view covers RenderPinholeFor's render
};

struct RobotMjcf {
  std::string xml;                // the <mujoco> document
  std::vector<GeomLabel> labels;  // the robot's geoms (class kRobot)
};

// The robot of this URDF with the rig's cameras. Throws InputError naming the URDF for geometry
// or joints it does not convert (meshes; prismatic, floating and planar joints).
RobotMjcf ComposeRobot(const robot::RobotDescription& robot, const robot::CameraRig& rig,
                       const RobotMjcfOptions& options = {});

// Where the nominal robot's MJCF lives in the robot folder (the project's robot/).
inline constexpr const char* kRobotMjcfFile = "mjcf/trimbot.xml";

// The robot in `robot_dir` (robot::RobotFiles::InFolder) at the world's origin, with its nominal
// calibration and without oversampling: what kRobotMjcfFile holds. trimbot_robot_mjcf writes it,
// and a test fails when the checked-in file differs from it.
std::string NominalRobotMjcf(const std::string& robot_dir);

}  // namespace trimbot::sim
