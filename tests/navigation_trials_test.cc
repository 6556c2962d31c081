// Navigation scenarios and batches: the scenario files, their bad-input errors, a closed-loop
// trial with injected faults, shards merged into the whole batch, and trials that time out.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "runner/batch.h"
#include "runner/scenario.h"
#include "test_support.h"
#include "runner/prior_knowledge.h"
#include "runner/trial.h"
#include "trimbot/common/input_error.h"
#include "trimbot/garden/garden.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/stack/global_planner.h"
#include "trimbot/stack/occupancy_grid.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

// The smoke scenario with `replace` -> `with` applied to its text, written to a temp file.
std::string SmokeVariant(const std::string& name, const std::string& replace, const std::string& with) {
  std::string text = ReadText(testing::SourcePath("scenarios/navigation/smoke.yaml"));
  if (!replace.empty()) text = std::regex_replace(text, std::regex(replace), with);
  return testing::WriteTempFile(name, text);
}

TEST(Scenario, TheRealRobotsTrialSetsLoad) {
  for (const std::string name : {"rectangle", "hourglass"}) {
    const Scenario s = Scenario::Load(testing::SourcePath("scenarios/navigation/" + name + ".yaml"));
    EXPECT_EQ(s.name, name);
    EXPECT_EQ(s.goals.size(), 4u);
    EXPECT_EQ(s.trials, 6);
    EXPECT_NEAR((s.goals.back() - Eigen::Vector2d(s.world.start.x, s.world.start.y)).norm(), 0.0, 1e-9) << "a loop";
    ASSERT_TRUE(s.stack.has_value());
    EXPECT_EQ(StackParametersFor(s, ProjectPaths{TRIMBOT_SOURCE_DIR}).localization,
              stack::LocalizationSource::kSimulatedPoseFixes);
    EXPECT_GT(s.initial_position_sigma, 0.0) << "never the true start";
    EXPECT_FALSE(s.criteria.empty());
  }
}

// Between consecutive hourglass goals the straight line is blocked for the robot (as in the real
// trials, it has to plan around the bushes).
TEST(Scenario, HourglassHasNoStraightPathBetweenGoals) {
  const Scenario s = Scenario::Load(testing::SourcePath("scenarios/navigation/hourglass.yaml"));
  const garden::OccupancyMap prior = PriorMap(s, ProjectPaths{TRIMBOT_SOURCE_DIR});
  const stack::OccupancyGrid map(prior.occupied, prior.resolution, prior.origin);
  const double radius = stack::PlannerParameters{}.robot_radius;
  Eigen::Vector2d from(s.world.start.x, s.world.start.y);
  for (const auto& goal : s.goals) {
    EXPECT_GE(map.DistanceToObstacle(goal), radius) << "goal " << goal.transpose() << " is not reachable";
    double closest = 1e9;
    for (double f = 0.0; f <= 1.0; f += 0.005) closest = std::min(closest, map.DistanceToObstacle(from + f * (goal - from)));
    EXPECT_LT(closest, radius) << "straight path from " << from.transpose() << " to " << goal.transpose();
    from = goal;
  }
}

TEST(Scenario, BadFilesNameTheFileLineAndKey) {
  const struct {
    std::string replace, with, expected;
  } cases[] = {
      {"goal_tolerance: 0.3", "goal_tolerence: 0.3", "goal_tolerence"},
      {"trials: 1", "trials: many", "trials"},
      {"time_limit: 60.0", "time_limit: 60.0\nfaults:\n  - {type: gremlins, start: 1.0}", "gremlins"},
      {"collisions: \\{max: 0\\}", "colisions: {max: 0}", "colisions"},
      {"success_rate: \\{min: 1.0\\}", "success_rate: {min: 1.0, max: 2.0}", "exactly one"},
      {"goal_tolerance: 0.3", "goal_tolerance: -0.3", "goal_tolerance"},
      {"goal_tolerance: 0.3", "goal_tolerance: 0.3\ngoal_tolerance: 0.4", "appears twice"},
      {"time_limit: 60.0", "time_limit: .inf", "finite"},
      {"position: 0.02", "position: -1", "initial_pose_sigma.position"},
      {"time_limit: 60.0", "time_limit: 60.0\nsurvey: {growth: 2}", "survey.growth"},
      {"start: \\{x: 0.0", "start: {x: .nan", "finite"},
  };
  for (const auto& c : cases) {
    const std::string path = SmokeVariant("bad_scenario.yaml", c.replace, c.with);
    try {
      Scenario::Load(path);
      ADD_FAILURE() << "no error for " << c.with;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      EXPECT_NE(message.find(c.expected), std::string::npos) << message;
      EXPECT_NE(message.find("line"), std::string::npos) << message;
    }
  }
}

// One trial in closed loop, directly: with pose fixes it arrives; with the cameras out for the whole
// run no fix arrives; a slipping left wheel bends the wheel odometry's heading. The summary says
// what was injected.
TEST(Trial, FaultsAreInjectedAndShowInTheResult) {
  const ProjectPaths paths{TRIMBOT_SOURCE_DIR};
  const std::string out = testing::TempDir("trial_faults");
  Scenario clean = Scenario::Load(SmokeVariant("fixes.yaml", "time_limit: 60.0",
                                               "time_limit: 60.0\nstack: {localization: simulated_pose_fixes}"));
  WritePriorMap(PriorMap(clean, paths), out + "/map");

  Scenario faulty = clean;
  sim::Fault dropout;
  dropout.kind = sim::Fault::Kind::kCameraDropout;
  dropout.start = 0.0;
  dropout.duration = 100.0;
  sim::Fault slip;
  slip.kind = sim::Fault::Kind::kWheelSlip;
  slip.start = 3.0;
  slip.duration = 6.0;
  slip.slip_left = 0.3;
  faulty.faults = {dropout, slip};

  auto run = [&](const Scenario& s, const std::string& name) {
    return RunTrial({&s, paths, out + "/map/map.yaml", out + "/" + name, 0, 3});
  };
  const TrialResult a = run(clean, "clean");
  const TrialResult b = run(faulty, "faulty");
  ASSERT_EQ(a.estimates.size(), 3u);
  EXPECT_TRUE(a.success) << a.status << " " << a.message;
  EXPECT_GT(a.estimates[2].position_m.size(), 20u) << "pose fixes at ~4 Hz over ~18 s";
  EXPECT_GT(a.fixes_accepted, 20);
  EXPECT_TRUE(b.estimates[2].position_m.empty()) << "fixes arrived with the cameras out";
  EXPECT_EQ(b.fixes_accepted, 0);
  ASSERT_EQ(b.faults.size(), 2u);
  EXPECT_NE(b.faults[0].find("camera dropout"), std::string::npos) << b.faults[0];
  EXPECT_NE(b.faults[1].find("wheel slip left 0.300"), std::string::npos) << b.faults[1];
  // 30 % extra counts on the left wheel for 6 s at 0.25 m/s: odometry believes in a right turn of
  // about 0.3 * 1.5 m / 0.46 m ~ 1 rad.
  const auto worst = [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); };
  EXPECT_LT(worst(a.estimates[1].heading_deg), 5.0);
  EXPECT_GT(worst(b.estimates[1].heading_deg), 30.0);
  EXPECT_TRUE(fs::exists(out + "/faulty/ground_truth.tum"));
  EXPECT_TRUE(fs::exists(out + "/faulty/result.json"));
}

TEST(Batch, ShardsMergeIntoTheWholeBatchAndTrialsReplayBySeed) {
  const std::string root = testing::TempDir("batch_shards");
  fs::remove_all(root);
  BatchOptions options;
  options.scenario_path = testing::SourcePath("scenarios/navigation/smoke.yaml");
  options.paths = {TRIMBOT_SOURCE_DIR};
  options.trials = 2;
  options.seed = 40;
  options.shard_count = 2;
  for (int shard = 0; shard < 2; ++shard) {
    options.shard_index = shard;
    options.out_dir = root + "/shard" + std::to_string(shard);
    EXPECT_EQ(RunBatch(options), 0);
  }
  ASSERT_EQ(MergeShards({root + "/shard0", root + "/shard1"}, root + "/merged"), 0);
  const json summary = ReadJson(root + "/merged/summary.json");
  ASSERT_EQ(summary["trials"].size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(summary["trials"][i]["index"], i);
    EXPECT_EQ(summary["trials"][i]["seed"], 40 + i);
    EXPECT_TRUE(summary["trials"][i]["success"].get<bool>());
  }
  EXPECT_EQ(summary["metrics"]["success_rate"], 1.0);
  EXPECT_TRUE(summary["pass"].get<bool>());
  EXPECT_NE(ReadText(root + "/merged/junit.xml").find("tests=\""), std::string::npos);
  EXPECT_TRUE(fs::exists(root + "/merged/trajectories.png"));
  EXPECT_TRUE(fs::exists(root + "/merged/localization_errors.png"));

  // Trial 1 (seed 41) replayed on its own gives the same ground-truth trajectory, to the digit.
  BatchOptions replay = options;
  replay.shard_index = 0;
  replay.shard_count = 1;
  replay.trials = 1;
  replay.seed = 41;
  replay.out_dir = root + "/replay";
  EXPECT_EQ(RunBatch(replay), 0);
  const std::string original = ReadText(root + "/merged/trials/001/ground_truth.tum");
  EXPECT_FALSE(original.empty());
  EXPECT_EQ(ReadText(root + "/replay/trials/000/ground_truth.tum"), original);
  EXPECT_NE(ReadText(root + "/merged/trials/000/ground_truth.tum"), original) << "another seed, another run";
}

TEST(Batch, ATrialThatTimesOutIsRecordedWithItsSeedAndTheBatchGoesOn) {
  const std::string out = testing::TempDir("batch_timeout");
  fs::remove_all(out);
  BatchOptions options;
  options.scenario_path = SmokeVariant("timeout.yaml", "time_limit: 60.0", "time_limit: 60.0\nwall_time_limit: 0.2");
  options.paths = {TRIMBOT_SOURCE_DIR};
  options.trials = 2;
  options.out_dir = out;
  EXPECT_EQ(RunBatch(options), 1) << "a failed criterion is exit code 1";
  const json summary = ReadJson(out + "/summary.json");
  ASSERT_EQ(summary["trials"].size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(summary["trials"][i]["status"], "timeout");
    EXPECT_EQ(summary["trials"][i]["seed"], 1 + i);
    EXPECT_FALSE(summary["trials"][i]["success"].get<bool>());
  }
  EXPECT_FALSE(summary["pass"].get<bool>());
  const std::string junit = ReadText(out + "/junit.xml");
  EXPECT_NE(junit.find("<failure"), std::string::npos);
}

}  // namespace
}  // namespace trimbot::scenarios
