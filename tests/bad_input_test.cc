// Hostile and careless input (issue 17): a corpus of malformed inputs generated from the project's
// own good files (bad_input_corpus.h) for the scenario, stack parameters, drive plan and map, plus
// relations between keys and the GardenUI CSV. Each must be refused with an InputError naming the
// file and the key (or line) - no crash, no hang, no silent acceptance. The garden, robot
// parameters, camchain and pair file readers are in reader_input_test.cc, which tests/fuzz also
// builds with AddressSanitizer and UndefinedBehaviorSanitizer.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "bad_input_corpus.h"
#include "loop/drive_plan.h"
#include "loop/prior_knowledge.h"
#include "loop/scenario.h"
#include "trimbot/common/input_error.h"
#include "trimbot/garden/garden.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/stack/stack_parameters.h"

namespace trimbot::scenarios {
namespace {

using testing::BadInput;
using testing::ExpectAllRefused;
using testing::kEverything;
using testing::MutateYaml;
using testing::NodePath;
using testing::ReadFile;

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
  - {trim_bush: 2, side_deg: 90.0}
cutting_path_database: paths.sqlite
goal_tolerance: 0.3
bush_tolerance: {distance: 0.1, bearing_deg: 5.0}
conditions: {time_of_day: 11.0, day_of_year: 250, shadows: true, growth: 0.5,
             wind: {mean_speed: 3.5, roughness_length: 0.1},
             clouds: {cover: 0.6, mean_shadow_duration: 60.0, direct_transmittance: 0.05, edge_duration: 5.0}}
map: {resolution: 0.05, clearance_height: 1.0}
survey: {growth: 0.2, unmapped: [9]}
initial_pose_sigma: {position: 0.02, yaw_deg: 0.5}
calibration_error: {focal_relative: 0.01, principal_point_px: 1.0, rotation_deg: 0.1, translation_m: 0.001,
                    camera_imu_time_offset_s: 0.001}
cameras: {render: false, resolution_scale: 0.5, motion_blur: true}
noise: {imu: 1.0, wheel_slip: 1.0}
simulated_pose_fixes: {availability: 0.9, outage_mean_duration: 1.5, position_sigma: 0.1, yaw_sigma_deg: 2.0, latency_median: 0.2,
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
robot_reference:
  source: the robot's figures
  metrics: {success_rate: 1.0, pose_fixes_position_error_mean_m: 0.08}
  frame_seconds: 0.15
)";

void LoadScenario(const std::string& path) {
  const Scenario scenario = Scenario::Load(path);
  StackParametersFor(scenario, kPaths);  // the stack section's keys
  ResolveGarden(scenario.setting, kPaths);
}

TEST(BadInput, ScenarioValuesAreCheckedAndNamed) {
  // Free text is free; every other value is checked.
  const auto wanted = [](const NodePath& p) {
    return p.empty() || (p[0].key != "name" && p[0].key != "description" && p.back().key != "source");
  };
  const int cases =
      ExpectAllRefused("scenario", kKitchenSinkScenario, MutateYaml(kKitchenSinkScenario, wanted), LoadScenario);
  std::cout << "scenario: " << cases << " malformed inputs refused\n";
}

TEST(BadInput, StackParametersAreCheckedAndNamed) {
  const std::string stack = ReadFile(testing::SourcePath("robot/config/stack.yaml"));
  const int cases = ExpectAllRefused("stack", stack, MutateYaml(stack, kEverything),
                                     [](const std::string& path) { stack::StackParameters::Load(path); });
  std::cout << "stack parameters: " << cases << " malformed inputs refused\n";
}

TEST(BadInput, DrivePlanAndMapAreCheckedAndNamed) {
  const std::string plan = ReadFile(testing::SourcePath("scenarios/drive_plans/lawn_loop.yaml"));
  int cases = ExpectAllRefused("drive_plan", plan, MutateYaml(plan, kEverything),
                               [](const std::string& path) { DrivePlan::Load(path); });
  const std::string map_dir = testing::TempDir("bad_input_map_image");
  garden::OccupancyMap map;
  map.occupied = cv::Mat::zeros(10, 20, CV_8U);
  map.resolution = 0.1;
  map.origin = Eigen::Vector2d::Zero();
  garden::WriteOccupancyMap(map, map_dir, "map");
  const std::string map_yaml = "image: " + map_dir +
                               "/map.png\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
                               "occupied_thresh: 0.65\nfree_thresh: 0.196\n";
  const auto not_image = [](const NodePath& p) { return p.empty() || p[0].key != "image"; };
  cases += ExpectAllRefused("occupancy", map_yaml, MutateYaml(map_yaml, not_image),
                            [](const std::string& path) { stack::OccupancyGrid::LoadMapServer(path); });
  std::cout << "drive plan and map: " << cases << " malformed inputs refused\n";
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
      {"fixes stating no error", with("position_sigma: 0.1", "position_sigma: 0.0"), "position_sigma"},
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
      {"stack key unknown", with("stack: {localization: simulated_pose_fixes}", "stack: {localisation: none}"),
       "localisation"},
  };
  int cases = ExpectAllRefused("relations_scenario", base, scenarios, LoadScenario);

  std::cout << "relations: " << cases << " malformed inputs refused\n";
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
  ExpectAllRefused(
      "gardenui", header + good, cases, [](const std::string& path) { garden::ImportGardenUiCsv(path, -1.48); },
      ".csv");
}

}  // namespace
}  // namespace trimbot::scenarios
