#include "trimbot/robot/robot_files.h"

#include "trimbot/robot/robot_description.h"

namespace trimbot::robot {

RobotFiles RobotFiles::InFolder(const std::string& robot_dir) {
  return {robot_dir + "/urdf/trimbot.urdf", robot_dir + "/calibration/nominal_camchain.yaml",
          robot_dir + "/config/robot_parameters.yaml", robot_dir + "/config/stack.yaml"};
}

CameraRig LoadCameraRig(const RobotFiles& files) {
  return CameraRig::LoadKalibr(files.camchain,
                               RobotDescription::Load(files.urdf).FramePose(RobotFrames::CameraOptical(0)));
}

}  // namespace trimbot::robot
