#pragma once
// The parts of RobotStack that its components share: the robot as the stack knows it, the pose
// estimators, the navigator, the arm and the mission. RobotStack owns one; the ring-frame
// components read it to decide when they are due and feed it what they perceive (RingComponent).
#include <Eigen/Core>
#include <memory>

#include "mission.h"
#include "trimbot/arm/arm_executive.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/stack/base_outline.h"
#include "trimbot/stack/ekf.h"
#include "trimbot/stack/navigator.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/stack/stack_parameters.h"
#include "trimbot/stack/wheel_odometry.h"
#include "trimbot/trimming/trim_executive.h"

namespace trimbot::stack {

struct StackState {
  // Throws InputError naming the file and key when a robot file is missing or malformed.
  StackState(const robot::RobotFiles& files, const StackParameters& parameters);
  StackState(const StackState&) = delete;
  StackState& operator=(const StackState&) = delete;

  robot::RobotDescription description;
  robot::CameraRig rig;
  BaseOutline outline;  // the base's, from the URDF's collision geometry
  int ticks_per_revolution = 0;
  WheelOdometry odometry;
  GyroOdometry servo_odometry;  // the bush servo's frame
  Ekf ekf;
  Pose2 odom_origin;  // map pose of the odom frame
  std::unique_ptr<OccupancyGrid> map;
  std::unique_ptr<Navigator> navigator;  // made with the map
  Eigen::Vector2d arm_axis;              // base_link: the arm's base (the ring's centre)
  arm::ArmExecutive arm;
  trimming::TrimExecutive trim;
  Mission mission;
  double last_linear_command = 0.0;  // m/s: its sign is the direction of travel
};

}  // namespace trimbot::stack
