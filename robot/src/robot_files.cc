#include "trimbot/robot/robot_files.h"

namespace trimbot::robot {

RobotFiles RobotFiles::InFolder(const std::string& robot_dir) {
  return {robot_dir + "/urdf/trimbot.urdf", robot_dir + "/calibration/nominal_camchain.yaml",
          robot_dir + "/config/robot_parameters.yaml", robot_dir + "/config/stack.yaml"};
}

}  // namespace trimbot::robot
