// libFuzzer target: the same bytes as a garden, robot parameters and a Kalibr camchain.
#include <Eigen/Geometry>

#include "fuzz_input.h"
#include "trimbot/garden/garden.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_parameters.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace trimbot;
  const std::string path = fuzz::WriteInput(data, size, ".yaml");
  fuzz::ExpectOnlyInputErrors([&] { garden::Garden::Load(path); });
  fuzz::ExpectOnlyInputErrors([&] { robot::RobotParameters::Load(path); });
  fuzz::ExpectOnlyInputErrors([&] { robot::CameraRig::LoadKalibr(path, Eigen::Isometry3d::Identity()); });
  return 0;
}
