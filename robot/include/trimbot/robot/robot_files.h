#pragma once
// The files that describe one robot: the simulator builds the plant from them and the stack builds
// the robot software from them (each reads only what it needs). Nothing else configures either.
#include <string>

#include "trimbot/robot/camera_rig.h"

namespace trimbot::robot {

struct RobotFiles {
  std::string urdf;              // geometry, joints, frames
  std::string camchain;          // Kalibr camera calibration of the ring
  std::string robot_parameters;  // sensors, rates, drive limits, arm home (config/robot_parameters.yaml)
  std::string stack_parameters;  // the robot software's parameters (config/stack.yaml)

  // The files of the robot in `robot_dir` (the project's robot/ folder): urdf/trimbot.urdf,
  // calibration/nominal_camchain.yaml, config/robot_parameters.yaml, config/stack.yaml.
  static RobotFiles InFolder(const std::string& robot_dir);
};

// The ring as these files describe it: the camchain's cameras, placed on base_link by cam0's frame
// in the URDF. Throws InputError naming the file that is missing or malformed.
CameraRig LoadCameraRig(const RobotFiles& files);

}  // namespace trimbot::robot
