// Writes the nominal robot's MJCF (sim/robot_mjcf.h: NominalRobotMjcf) from the URDF and the
// nominal calibration in a robot folder: after a change to either, or to the robot's MJCF
// composition, run
//   trimbot_robot_mjcf robot/
// to rewrite robot/mjcf/trimbot.xml (the simulator tests fail until the file is what they give).
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/sim/robot_mjcf.h"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s ROBOT_FOLDER [OUTPUT]   (OUTPUT: ROBOT_FOLDER/%s)\n", argv[0],
                 trimbot::sim::kRobotMjcfFile);
    return 2;
  }
  const std::string robot_dir = argv[1];
  const std::filesystem::path output =
      argc == 3 ? std::filesystem::path(argv[2]) : std::filesystem::path(robot_dir) / trimbot::sim::kRobotMjcfFile;
  try {
    const std::string xml = trimbot::sim::NominalRobotMjcf(robot_dir);
    if (output.has_parent_path()) std::filesystem::create_directories(output.parent_path());
    trimbot::WriteFileAtomically(output.string(), xml);
  } catch (const trimbot::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", output.string().c_str(), e.what());
    return 1;
  }
  std::printf("wrote %s\n", output.string().c_str());
  return 0;
}
