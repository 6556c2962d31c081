// The visual map cache (scenarios/harness/runners/map_cache.h): its key changes when any input of the map
// changes and not otherwise, and a cached map is found only under its own key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "runners/map_cache.h"
#include "test_support.h"

namespace trimbot {
namespace {

namespace fs = std::filesystem;
using scenarios::MapCacheKey;
using scenarios::MapRecipe;
using scenarios::ProjectPaths;

// Replaces the first `from` in a file by `to` (the test fails if there is none).
void Edit(const std::string& path, const std::string& from, const std::string& to) {
  std::string text = testing::ReadText(path);
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << path << " has no '" << from << "'";
  text.replace(at, from.size(), to);
  std::ofstream(path) << text;
}

// A private copy of the project's data (robot files, gardens) and of the lawn's drive plan, so the
// test can change each input of the map in turn.
class MapCacheKeyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::TempDir("map_cache_key_" +
                             std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(root_);
    fs::create_directories(root_ + "/garden_scenes");
    fs::copy(testing::SourcePath("robot"), root_ + "/robot", fs::copy_options::recursive);
    fs::copy(testing::SourcePath("garden_scenes/gardens"), root_ + "/garden_scenes/gardens",
             fs::copy_options::recursive);
    fs::copy(testing::SourcePath("scenarios/drive_plans/lawn_loop.yaml"), root_ + "/plan.yaml");
    recipe_ = MapRecipe{};
    recipe_.plan_path = root_ + "/plan.yaml";
    recipe_.descriptor = visual_localization::Descriptor::kUprightSift;
    paths_ = {root_};
    key_ = MapCacheKey(recipe_, paths_);
  }

  // Whether the key differs from the original one after `change`.
  bool KeyChangesWith(const std::function<void()>& change) {
    change();
    return MapCacheKey(recipe_, paths_) != key_;
  }

  std::string root_;
  MapRecipe recipe_;
  ProjectPaths paths_;
  std::string key_;
};

TEST_F(MapCacheKeyTest, TheSameInputsGiveTheSameKey) {
  EXPECT_EQ(MapCacheKey(recipe_, paths_), key_);
  EXPECT_EQ(scenarios::MapCacheId(key_).size(), 16u);
  EXPECT_EQ(scenarios::MapCacheId(key_), scenarios::MapCacheId(MapCacheKey(recipe_, paths_)));
}

TEST_F(MapCacheKeyTest, WhatTheMapDoesNotDependOnLeavesTheKey) {
  EXPECT_FALSE(
      KeyChangesWith([&] { Edit(root_ + "/plan.yaml", "# Headless drive", "# A comment changed. Headless drive"); }));
  EXPECT_FALSE(
      KeyChangesWith([&] { Edit(root_ + "/robot/config/stack.yaml", "cruise_speed: 0.25", "cruise_speed: 0.3"); }));
  EXPECT_FALSE(KeyChangesWith([&] {
    Edit(root_ + "/garden_scenes/gardens/wageningen.yaml", "name: wageningen", "name: wageningen  # another garden");
  }));
  EXPECT_FALSE(KeyChangesWith([&] {
    fs::copy(root_ + "/plan.yaml", root_ + "/elsewhere.yaml");
    recipe_.plan_path = root_ + "/elsewhere.yaml";
  })) << "the plan's content counts, not its path";
}

TEST_F(MapCacheKeyTest, EveryInputOfTheMapChangesTheKey) {
  EXPECT_TRUE(KeyChangesWith([&] { Edit(root_ + "/plan.yaml", "seed: 1", "seed: 2"); }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith(
      [&] { Edit(root_ + "/plan.yaml", "{duration: 16.8, linear: 0.25", "{duration: 16.9, linear: 0.25"); }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith(
      [&] { Edit(root_ + "/garden_scenes/gardens/test_lawn.yaml", "position: [3.0, 1.2]", "position: [3.1, 1.2]"); }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith([&] { Edit(root_ + "/robot/calibration/nominal_camchain.yaml", "540.0", "541.0"); }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith([&] { Edit(root_ + "/robot/urdf/trimbot.urdf", "<robot", "<!-- changed --><robot"); }));
  SetUp();
  EXPECT_TRUE(
      KeyChangesWith([&] { Edit(root_ + "/robot/config/robot_parameters.yaml", "rate_hz: 200.0", "rate_hz: 100.0"); }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith([&] { recipe_.descriptor = visual_localization::Descriptor::kSift; }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith([&] { recipe_.seed = 7; }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith([&] { recipe_.seconds = 20.0; }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith([&] { recipe_.survey_position_sigma = 0.05; }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith([&] { recipe_.survey_rotation_sigma_deg = 1.0; }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith([&] { recipe_.builder = visual_localization::KeyframePoses::kSurveyed; }));
  SetUp();
  // The log builder's odometry runs the stack's EKF.
  EXPECT_TRUE(
      KeyChangesWith([&] { Edit(root_ + "/robot/config/stack.yaml", "gyro_sigma: 0.005", "gyro_sigma: 0.006"); }));
  SetUp();
  EXPECT_TRUE(KeyChangesWith([&] { Edit(root_ + "/plan.yaml", "garden: test_lawn", "garden: wageningen"); }));
}

// A scenario driven by the stack as the mapping drive: its navigation parameters shape the drive.
TEST_F(MapCacheKeyTest, AScenarioAsTheMappingDriveCountsTheStackParameters) {
  fs::copy(testing::SourcePath("scenarios/navigation/smoke.yaml"), root_ + "/scenario.yaml");
  recipe_.plan_path = root_ + "/scenario.yaml";
  key_ = MapCacheKey(recipe_, paths_);
  EXPECT_TRUE(
      KeyChangesWith([&] { Edit(root_ + "/robot/config/stack.yaml", "cruise_speed: 0.25", "cruise_speed: 0.3"); }));
}

TEST_F(MapCacheKeyTest, ACachedMapIsFoundOnlyUnderItsOwnKey) {
  const std::string cache = root_ + "/cache";
  EXPECT_EQ(scenarios::FindCachedMap(recipe_, paths_, cache), "");
  const std::string folder = cache + "/" + scenarios::MapCacheId(key_);
  fs::create_directories(folder);
  std::ofstream(folder + "/map.sqlite") << "a map";
  std::ofstream(folder + "/key.txt") << key_ << "a line of another key\n";
  EXPECT_EQ(scenarios::FindCachedMap(recipe_, paths_, cache), "") << "a key.txt of another key is not this map";
  std::ofstream(folder + "/key.txt") << key_;
  EXPECT_EQ(scenarios::FindCachedMap(recipe_, paths_, cache), folder + "/map.sqlite");
  const scenarios::CachedMap found = scenarios::EnsureCachedMap(recipe_, paths_, cache);
  EXPECT_FALSE(found.built);
  EXPECT_EQ(found.path, folder + "/map.sqlite");
  EXPECT_EQ(testing::ReadText(found.path), "a map") << "found, not rebuilt";
}

}  // namespace
}  // namespace trimbot
