// Hostile and careless input (issue 17): a corpus of malformed inputs generated from the project's
// own good files. Every value of every YAML input is replaced in turn by NaN, infinities, garbage,
// absurd magnitudes and wrong types; every map gets an unknown key; the hand-written formats (pair
// files, GardenUI CSV) get broken numbers, counts and rotations. Each must be refused with an
// InputError naming the file and the key (or line) - no crash, no hang, no silent acceptance.
// The count of cases is printed; the test fails below 200.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "cli/registration_command.h"
#include "runner/drive_plan.h"
#include "runner/prior_knowledge.h"
#include "runner/scenario.h"
#include "test_support.h"
#include "trimbot/common/input_error.h"
#include "trimbot/garden/garden.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_parameters.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/stack/stack_parameters.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;

// One malformed input: the file's text, and what its error must name besides the file.
struct BadInput {
  std::string description;
  std::string text;
  std::string must_name;
};

// A scalar's place in a YAML tree: map keys and sequence indices from the root.
struct Step {
  std::string key;  // empty for a sequence index
  std::size_t index = 0;
};
using NodePath = std::vector<Step>;

YAML::Node At(YAML::Node node, const NodePath& path) {
  for (const Step& step : path) node.reset(step.key.empty() ? node[step.index] : node[step.key]);
  return node;
}

// The innermost map key on the path: what the error message must name.
std::string KeyOf(const NodePath& path) {
  for (auto it = path.rbegin(); it != path.rend(); ++it) {
    if (!it->key.empty()) return it->key;
  }
  return "";
}

std::string Describe(const NodePath& path) {
  std::string text;
  for (const Step& step : path) text += step.key.empty() ? "[" + std::to_string(step.index) + "]" : "." + step.key;
  return text;
}

void CollectLeaves(const YAML::Node& node, NodePath& path, const std::function<bool(const NodePath&)>& wanted,
                   std::vector<NodePath>* scalars, std::vector<NodePath>* maps) {
  if (node.IsMap()) {
    if (wanted(path)) maps->push_back(path);
    for (const auto& entry : node) {
      path.push_back({entry.first.as<std::string>(), 0});
      CollectLeaves(entry.second, path, wanted, scalars, maps);
      path.pop_back();
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      path.push_back({"", i});
      CollectLeaves(node[i], path, wanted, scalars, maps);
      path.pop_back();
    }
  } else if (node.IsScalar() && wanted(path)) {
    scalars->push_back(path);
  }
}

bool IsNumber(const std::string& text) {
  try {
    YAML::Node(text).as<double>();
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}

std::string Emit(const YAML::Node& root) {
  YAML::Emitter out;
  out << root;
  return std::string(out.c_str()) + "\n";
}

// Every scalar replaced by values no key accepts, and every map given an unknown key.
std::vector<BadInput> MutateYaml(const std::string& good_text, const std::function<bool(const NodePath&)>& wanted) {
  const YAML::Node good = YAML::Load(good_text);
  std::vector<NodePath> scalars, maps;
  NodePath path;
  CollectLeaves(good, path, wanted, &scalars, &maps);
  std::vector<BadInput> cases;
  for (const NodePath& leaf : scalars) {
    const std::string value = At(good, leaf).Scalar();
    std::vector<std::string> replacements = {"[1, 2]", "{a: 1}"};
    if (IsNumber(value)) {
      replacements.insert(replacements.end(), {".nan", ".inf", "-.inf", "1.5abc", "1.0e308", "-1.0e308"});
    } else if (value == "true" || value == "false") {
      replacements.push_back("maybe");
    }
    for (const std::string& replacement : replacements) {
      YAML::Node copy = YAML::Clone(good);
      At(copy, leaf) = YAML::Load(replacement);
      cases.push_back({Describe(leaf) + " = " + replacement, Emit(copy), KeyOf(leaf)});
    }
  }
  for (const NodePath& map : maps) {
    YAML::Node copy = YAML::Clone(good);
    At(copy, map)["bogus_key"] = 1;
    cases.push_back({Describe(map) + ".bogus_key", Emit(copy), "bogus_key"});
  }
  return cases;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Writes each case to a file and checks that `load` refuses it, naming the file and the key.
// The good file the cases were made from must load: otherwise every case would be refused for
// the good file's fault and the test would prove nothing.
int ExpectAllRefused(const std::string& kind, const std::string& good, const std::vector<BadInput>& cases,
                     const std::function<void(const std::string&)>& load, const std::string& extension = ".yaml") {
  const std::string dir = testing::TempDir("bad_input_" + kind);
  const std::string good_path = dir + "/good" + extension;
  std::ofstream(good_path) << good;
  try {
    load(good_path);
  } catch (const std::exception& e) {
    ADD_FAILURE() << kind << ": the good file is refused: " << e.what();
    return 0;
  }
  int index = 0;
  for (const BadInput& bad : cases) {
    const std::string path = dir + "/case_" + std::to_string(index++) + extension;
    std::ofstream(path) << bad.text;
    try {
      load(path);
      ADD_FAILURE() << kind << ": accepted " << bad.description;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << kind << " " << bad.description << ": " << message;
      EXPECT_NE(message.find(bad.must_name), std::string::npos)
          << kind << " " << bad.description << ": does not name '" << bad.must_name << "': " << message;
    } catch (const std::exception& e) {
      ADD_FAILURE() << kind << " " << bad.description << ": not an input error: " << e.what();
    }
  }
  return static_cast<int>(cases.size());
}

const auto kEverything = [](const NodePath&) { return true; };

const ProjectPaths kPaths{TRIMBOT_SOURCE_DIR};

// A scenario that uses every section a navigation scenario can have.
const char* kKitchenSinkScenario = R"(
name: kitchen_sink
description: every section
garden: test_lawn
start: {x: 0.0, y: 0.0, yaw_deg: 10.0}
goals:
  - {x: 4.0, y: 0.0}
  - {approach_bush: 1}
goal_tolerance: 0.3
bush_tolerance: {distance: 0.1, bearing_deg: 5.0}
conditions: {time_of_day: 11.0, day_of_year: 250, shadows: true, growth: 0.5}
map: {resolution: 0.05, clearance_height: 1.0}
survey: {growth: 0.2, unmapped: [9]}
initial_pose_sigma: {position: 0.02, yaw_deg: 0.5}
calibration_error: {focal_relative: 0.01, principal_point_px: 1.0, rotation_deg: 0.1, translation_m: 0.001}
cameras: {render: false, resolution_scale: 0.5}
noise: {imu: 1.0, wheel_slip: 1.0}
simulated_pose_fixes: {availability: 0.9, position_sigma: 0.1, yaw_sigma_deg: 2.0, latency_median: 0.2,
                       latency_log_sigma: 0.3, latency_max: 1.0, outlier_probability: 0.05, outlier_min: 0.5,
                       outlier_max: 2.0}
faults:
  - {type: wheel_slip, start: 5.0, duration: 2.0, left: 0.3, right: 0.0}
  - {type: imu_bias_jump, time: 3.0, gyro: [0.0, 0.0, 0.01], accel: [0.0, 0.1, 0.0]}
  - {type: camera_dropout, start: 1.0, duration: 1.0}
stack: {localization: simulated_pose_fixes}
seed: 1
trials: 2
time_limit: 60.0
wall_time_limit: 600.0
criteria:
  success_rate: {min: 1.0}
  collisions: {max: 0}
)";

void LoadScenario(const std::string& path) {
  const Scenario scenario = Scenario::Load(path);
  StackParametersFor(scenario, kPaths);  // the stack section's keys
  ResolveGarden(scenario.world, kPaths);
}

TEST(BadInput, ScenarioValuesAreCheckedAndNamed) {
  // Free text is free; every other value is checked.
  const auto wanted = [](const NodePath& p) { return p.empty() || (p[0].key != "name" && p[0].key != "description"); };
  const int cases = ExpectAllRefused("scenario", kKitchenSinkScenario, MutateYaml(kKitchenSinkScenario, wanted), LoadScenario);
  std::cout << "scenario: " << cases << " malformed inputs refused\n";
}

TEST(BadInput, GardenValuesAreCheckedAndNamed) {
  const auto wanted = [](const NodePath& p) { return p.empty() || p[0].key != "description"; };
  const std::string good = ReadFile(testing::SourcePath("garden_scenes/gardens/test_lawn.yaml"));
  const int cases = ExpectAllRefused("garden", good, MutateYaml(good, wanted),
                                     [](const std::string& path) { garden::Garden::Load(path); });
  std::cout << "garden: " << cases << " malformed inputs refused\n";
}

TEST(BadInput, RobotAndStackParametersAreCheckedAndNamed) {
  const std::string robot = ReadFile(testing::SourcePath("robot/config/robot_parameters.yaml"));
  int cases = ExpectAllRefused("robot_parameters", robot, MutateYaml(robot, kEverything),
                               [](const std::string& path) { robot::RobotParameters::Load(path); });
  const std::string stack = ReadFile(testing::SourcePath("robot/config/stack.yaml"));
  cases += ExpectAllRefused("stack", stack, MutateYaml(stack, kEverything),
                            [](const std::string& path) { stack::StackParameters::Load(path); });
  std::cout << "robot and stack parameters: " << cases << " malformed inputs refused\n";
}

TEST(BadInput, CalibrationDrivePlanAndMapAreCheckedAndNamed) {
  // The first two cameras stand for the ten.
  const auto first_cameras = [](const NodePath& p) { return p.empty() || p[0].key == "cam0" || p[0].key == "cam1"; };
  const std::string camchain = ReadFile(testing::SourcePath("robot/calibration/nominal_camchain.yaml"));
  int cases = ExpectAllRefused(
      "camchain", camchain, MutateYaml(camchain, first_cameras),
      [](const std::string& path) { robot::CameraRig::LoadKalibr(path, Eigen::Isometry3d::Identity()); });
  const std::string plan = ReadFile(testing::SourcePath("scenarios/drives/lawn_loop.yaml"));
  cases += ExpectAllRefused("drive_plan", plan, MutateYaml(plan, kEverything), [](const std::string& path) { DrivePlan::Load(path); });
  const std::string map_dir = testing::TempDir("bad_input_map_image");
  garden::OccupancyMap map;
  map.occupied = cv::Mat::zeros(10, 20, CV_8U);
  map.resolution = 0.1;
  map.origin = Eigen::Vector2d::Zero();
  garden::WriteOccupancyMap(map, map_dir, "map");
  const std::string map_yaml = "image: " + map_dir + "/map.png\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
                               "occupied_thresh: 0.65\nfree_thresh: 0.196\n";
  const auto not_image = [](const NodePath& p) { return p.empty() || p[0].key != "image"; };
  cases += ExpectAllRefused("occupancy", map_yaml, MutateYaml(map_yaml, not_image),
                            [](const std::string& path) { stack::OccupancyGrid::LoadMapServer(path); });
  std::cout << "calibration, drive plan and map: " << cases << " malformed inputs refused\n";
}

// Relations and ranges that no single replacement above reaches.
TEST(BadInput, RelationsAndRangesAreChecked) {
  const std::string base = kKitchenSinkScenario;
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string text = base;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  const std::vector<BadInput> scenarios = {
      {"outlier_min > outlier_max", with("outlier_min: 0.5", "outlier_min: 5.0"), "outlier_max"},
      {"latency_max < latency_median", with("latency_max: 1.0", "latency_max: 0.1"), "latency_max"},
      {"negative yaw sigma", with("yaw_sigma_deg: 2.0", "yaw_sigma_deg: -3"), "yaw_sigma_deg"},
      {"negative trials", with("trials: 2", "trials: -1"), "trials"},
      {"fractional trials", with("trials: 2", "trials: 1.5"), "trials"},
      {"negative seed", with("seed: 1", "seed: -1"), "seed"},
      {"fault before the start", with("start: 5.0", "start: -1.0"), "start"},
      {"zero fault duration", with("duration: 2.0", "duration: 0"), "duration"},
      {"slip of -1", with("left: 0.3", "left: -1.0"), "left"},
      {"unknown garden", with("garden: test_lawn", "garden: no_such_garden"), "no_such_garden"},
      {"unknown fault", with("type: camera_dropout", "type: meteor"), "type"},
      {"unknown metric", with("collisions: {max: 0}", "crashes: {max: 0}"), "crashes"},
      {"min and max", with("collisions: {max: 0}", "collisions: {min: 0, max: 1}"), "min"},
      {"duplicate key", with("seed: 1", "seed: 1\nseed: 2"), "seed"},
      {"map resolution 1e308", with("resolution: 0.05", "resolution: 1.0e308"), "resolution"},
      {"time of day 25 h", with("time_of_day: 11.0", "time_of_day: 25"), "time_of_day"},
      {"stack key unknown", with("stack: {localization: simulated_pose_fixes}", "stack: {localisation: none}"), "localisation"},
  };
  int cases = ExpectAllRefused("relations_scenario", base, scenarios, LoadScenario);

  const std::string camchain = ReadFile(testing::SourcePath("robot/calibration/nominal_camchain.yaml"));
  const auto camchain_with = [&](const std::string& from, const std::string& to) {
    std::string text = camchain;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  const YAML::Node cam0 = YAML::Load(camchain)["cam0"];
  std::ostringstream resolution;
  resolution << "resolution: [" << cam0["resolution"][0].as<std::string>() << ", " << cam0["resolution"][1].as<std::string>() << "]";
  std::ostringstream intrinsics;
  intrinsics << "intrinsics: [" << cam0["intrinsics"][0].as<std::string>();
  const std::vector<BadInput> camchains = {
      {"fractional resolution", camchain_with(resolution.str(), "resolution: [752.9, 480]"), "resolution"},
      {"huge resolution", camchain_with(resolution.str(), "resolution: [200000, 200000]"), "resolution"},
      {"tiny focal length", camchain_with(intrinsics.str(), "intrinsics: [1.0e-6"), "intrinsics"},
  };
  cases += ExpectAllRefused("relations_camchain", camchain, camchains,
                            [](const std::string& path) { robot::CameraRig::LoadKalibr(path, Eigen::Isometry3d::Identity()); });
  std::cout << "relations: " << cases << " malformed inputs refused\n";
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
  ExpectAllRefused("pair", PairText(), cases, [](const std::string& path) { LoadRegistrationPair(path); }, ".txt");
}

TEST(BadInput, GardenUiCsvIsCheckedAndNamed) {
  const std::string header = "id,label,shape,size_x,size_y,size_z,pos_x,pos_y,pos_z,yaw_deg\n";
  const std::string good = "2,Hedge-Ivy,box,0.760,6.432,1.372,9.693,0.429,-1.480,0\n";
  const std::vector<BadInput> cases = {
      {"NaN size", header + "2,Hedge-Ivy,box,nan,6.432,1.372,9.693,0.429,-1.480,0\n", "size_x"},
      {"infinite position", header + "2,Hedge-Ivy,box,0.76,6.432,1.372,inf,0.429,-1.480,0\n", "pos_x"},
      {"negative size", header + "2,Hedge-Ivy,box,0.76,-6.432,1.372,9.693,0.429,-1.480,0\n", "size_y"},
      {"garbage yaw", header + "2,Hedge-Ivy,box,0.76,6.432,1.372,9.693,0.429,-1.480,0abc\n", "yaw_deg"},
      {"fractional id", header + "2.5,Hedge-Ivy,box,0.76,6.432,1.372,9.693,0.429,-1.480,0\n", "id"},
      {"duplicate id", header + good + good, "duplicate id"},
      {"unknown label", header + "2,Spaceship-X,box,0.76,6.432,1.372,9.693,0.429,-1.480,0\n", "unknown label"},
      {"nine fields", header + "2,Hedge-Ivy,box,0.76,6.432,1.372,9.693,0.429,-1.480\n", "10 fields"},
      {"below the ground", header + "2,Hedge-Ivy,box,0.76,6.432,0.5,9.693,0.429,-3.0,0\n", "below the ground"},
      {"no objects", header, "no objects"},
  };
  ExpectAllRefused("gardenui", header + good, cases, [](const std::string& path) { garden::ImportGardenUiCsv(path, -1.48); }, ".csv");
}

}  // namespace
}  // namespace trimbot::scenarios
