// The readers that tests/fuzz also fuzzes and builds with AddressSanitizer and
// UndefinedBehaviorSanitizer (issue 17): garden, robot parameters, Kalibr camchain and the
// registration pair file. Each malformed input (bad_input_corpus.h, and hand-written cases for the
// pair file's lines and the camchain's ranges) must be refused with an InputError naming the file
// and the key or line. Light on purpose: only those readers' own sources and yaml-cpp.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <sstream>
#include <string>
#include <vector>

#include "bad_input_corpus.h"
#include "evaluation/registration_pair_file.h"
#include "trimbot/garden/garden.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_parameters.h"

namespace trimbot::scenarios {
namespace {

using testing::BadInput;
using testing::ExpectAllRefused;
using testing::kEverything;
using testing::MutateYaml;
using testing::NodePath;
using testing::ReadFile;

TEST(BadInput, GardenValuesAreCheckedAndNamed) {
  const auto wanted = [](const NodePath& p) { return p.empty() || p[0].key != "description"; };
  const std::string good = ReadFile(testing::SourcePath("garden_scenes/gardens/test_lawn.yaml"));
  const int cases = ExpectAllRefused("garden", good, MutateYaml(good, wanted),
                                     [](const std::string& path) { garden::Garden::Load(path); });
  std::cout << "garden: " << cases << " malformed inputs refused\n";
}

TEST(BadInput, RobotParametersAreCheckedAndNamed) {
  const std::string robot = ReadFile(testing::SourcePath("robot/config/robot_parameters.yaml"));
  const int cases = ExpectAllRefused("robot_parameters", robot, MutateYaml(robot, kEverything),
                                     [](const std::string& path) { robot::RobotParameters::Load(path); });
  std::cout << "robot parameters: " << cases << " malformed inputs refused\n";
}

void LoadCamchain(const std::string& path) { robot::CameraRig::LoadKalibr(path, Eigen::Isometry3d::Identity()); }

TEST(BadInput, CamchainValuesAreCheckedAndNamed) {
  // The first two cameras stand for the ten.
  const auto first_cameras = [](const NodePath& p) { return p.empty() || p[0].key == "cam0" || p[0].key == "cam1"; };
  const std::string camchain = ReadFile(testing::SourcePath("robot/calibration/nominal_camchain.yaml"));
  int cases = ExpectAllRefused("camchain", camchain, MutateYaml(camchain, first_cameras), LoadCamchain);
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string text = camchain;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  const YAML::Node cam0 = YAML::Load(camchain)["cam0"];
  std::ostringstream resolution;
  resolution << "resolution: [" << cam0["resolution"][0].as<std::string>() << ", "
             << cam0["resolution"][1].as<std::string>() << "]";
  std::ostringstream intrinsics;
  intrinsics << "intrinsics: [" << cam0["intrinsics"][0].as<std::string>();
  const std::vector<BadInput> ranges = {
      {"fractional resolution", with(resolution.str(), "resolution: [752.9, 480]"), "resolution"},
      {"huge resolution", with(resolution.str(), "resolution: [200000, 200000]"), "resolution"},
      {"tiny focal length", with(intrinsics.str(), "intrinsics: [1.0e-6"), "intrinsics"},
  };
  cases += ExpectAllRefused("camchain_ranges", camchain, ranges, LoadCamchain);
  std::cout << "camchain: " << cases << " malformed inputs refused\n";
}

// A good pair file, small: 4 points each.
std::string PairText(const std::string& r = "R 1 0 0 0 1 0 0 0 1", const std::string& t = "t 0.1 0.2 0.3",
                     const std::string& x_count = "4", const std::string& point = "0.5 0.5 0.5 1 0 0 1 0 1") {
  std::string text = "covariances relative\n" + r + "\n" + t + "\nX " + x_count + "\n";
  text += point + "\n1 0 0 1 0 0 1 0 1\n0 1 0 1 0 0 1 0 1\n0 0 1 1 0 0 1 0 1\nY 4\n";
  text += "0 0 0 1 0 0 1 0 1\n1 0 0 1 0 0 1 0 1\n0 1 0 1 0 0 1 0 1\n0 0 1 1 0 0 1 0 1\n";
  return text;
}

TEST(BadInput, RegistrationPairFilesAreCheckedAndNamed) {
  std::vector<BadInput> cases = {
      {"R of twos", PairText("R 2 2 2 2 2 2 2 2 2"), "'R' is not a rotation"},
      {"R a reflection", PairText("R 1 0 0 0 1 0 0 0 -1"), "'R' is not a rotation"},
      {"R with NaN", PairText("R nan 0 0 0 1 0 0 0 1"), "line 2"},
      {"R short", PairText("R 1 0 0 0 1 0 0 0"), "line 2"},
      {"R garbage", PairText("R 1 0 0 0 1 0 0 0 1abc"), "line 2"},
      {"t infinite", PairText("R 1 0 0 0 1 0 0 0 1", "t inf 0 0"), "line 3"},
      {"t 0.12abc", PairText("R 1 0 0 0 1 0 0 0 1", "t 0.12abc 0 0"), "line 3"},
      {"R twice", PairText("R 1 0 0 0 1 0 0 0 1\nR 1 0 0 0 1 0 0 0 1"), "appears twice"},
      {"no t", PairText("R 1 0 0 0 1 0 0 0 1", ""), "ground truth"},
      {"count garbage", PairText("R 1 0 0 0 1 0 0 0 1", "t 0 0 0", "four"), "line 4"},
      {"count negative", PairText("R 1 0 0 0 1 0 0 0 1", "t 0 0 0", "-4"), "line 4"},
      {"count too large", PairText("R 1 0 0 0 1 0 0 0 1", "t 0 0 0", "40"), "line 9"},
      {"point garbage", PairText("R 1 0 0 0 1 0 0 0 1", "t 0 0 0", "4", "0.5 0.5 0.5abc 1 0 0 1 0 1"), "line 5"},
      {"point short", PairText("R 1 0 0 0 1 0 0 0 1", "t 0 0 0", "4", "0.5 0.5 0.5 1 0 0 1 0"), "line 5"},
      {"point long", PairText("R 1 0 0 0 1 0 0 0 1", "t 0 0 0", "4", "0.5 0.5 0.5 1 0 0 1 0 1 7"), "line 5"},
      {"unknown line", "Q 1\n" + PairText(), "unexpected 'Q'"},
      {"unknown covariance kind", "covariances furlongs\n" + PairText().substr(21), "covariances"},
      {"empty file", "", "ground truth"},
  };
  ExpectAllRefused(
      "pair", PairText(), cases, [](const std::string& path) { LoadRegistrationPair(path); }, ".txt");
}

}  // namespace
}  // namespace trimbot::scenarios
