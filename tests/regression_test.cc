// Statistics of batch comparison, command-line overrides, and the regression check itself.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "evaluation/comparison.h"
#include "evaluation/statistics.h"
#include "loop/scenario.h"
#include "runners/ablation.h"
#include "runners/batch.h"
#include "runners/sweep.h"
#include "test_support.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/overrides.h"

namespace trimbot::scenarios {
namespace {

using nlohmann::json;

TEST(Statistics, WilsonIntervalsMatchTheFormula) {
  const Interval all = WilsonInterval(6, 6);
  EXPECT_NEAR(all.low, 0.6097, 1e-3);  // 6/6: the classic example
  EXPECT_DOUBLE_EQ(all.high, 1.0);
  const Interval half = WilsonInterval(5, 10);
  EXPECT_NEAR(half.low, 0.2366, 1e-3);
  EXPECT_NEAR(half.high, 0.7634, 1e-3);
}

TEST(Statistics, FisherAndMannWhitneyGiveTheirExactPValues) {
  // 6/6 against 2/6: P(X <= 2) for the hypergeometric(12, 8, 6) = (C(8,2)C(4,4)) / C(12,6) = 28/924.
  EXPECT_NEAR(FisherLowerP(6, 6, 2, 6), 28.0 / 924.0, 1e-12);
  EXPECT_NEAR(FisherLowerP(6, 6, 6, 6), 1.0, 1e-12);
  // Every b above every a, 6 against 6: the one most extreme of C(12,6) = 924 arrangements.
  const std::vector<double> a = {1, 2, 3, 4, 5, 6}, b = {7, 8, 9, 10, 11, 12};
  EXPECT_NEAR(MannWhitneyGreaterP(a, b), 1.0 / 924.0, 1e-12);
  EXPECT_NEAR(MannWhitneyGreaterP(b, a), 1.0, 1e-12);
  EXPECT_NEAR(MannWhitneyGreaterP({0, 0, 0}, {0, 0, 0}), 1.0, 1e-12) << "ties everywhere: no evidence";
  // Large samples take the normal approximation: a clear shift is still significant.
  std::vector<double> big_a, big_b;
  for (int i = 0; i < 30; ++i) big_a.push_back(i), big_b.push_back(i + 15);
  EXPECT_LT(MannWhitneyGreaterP(big_a, big_b), 1e-3);
  EXPECT_GT(MannWhitneyGreaterP(big_a, big_a), 0.3);
}

TEST(Statistics, PowerGrowsWithTrialsAndTheDrop) {
  EXPECT_LT(FisherPower(1.0, 0.9, 6, 0.01), 0.01);
  EXPECT_GT(FisherPower(1.0, 0.5, 40, 0.01), 0.9);
  const int n_small_drop = TrialsToDetect(1.0, 0.9, 0.01), n_big_drop = TrialsToDetect(1.0, 0.5, 0.01);
  EXPECT_GT(n_small_drop, n_big_drop);
  EXPECT_GE(FisherPower(1.0, 0.5, n_big_drop, 0.01), 0.8);
  EXPECT_LT(FisherPower(1.0, 0.5, n_big_drop - 1, 0.01), 0.8);
}

TEST(Overrides, SetNestedKeysAndAreCheckedLikeTheFile) {
  const std::string smoke = testing::SourcePath("scenarios/navigation/smoke.yaml");
  const Scenario s = Scenario::Load(smoke, ParseOverrides({"trials=3", "stack.navigation.follower.cruise_speed=0.3",
                                                           "initial_pose_sigma.yaw_deg=1"}));
  EXPECT_EQ(s.trials, 3);
  EXPECT_NEAR(s.initial_yaw_sigma, M_PI / 180.0, 1e-12);
  ASSERT_TRUE(s.stack.has_value());
  EXPECT_EQ(s.overrides.size(), 3u);
  EXPECT_NE(s.effective_yaml.find("--set trials=3"), std::string::npos);
  for (const std::string bad : {"trials=three", "goal_tolerance=-1", "speeed=1", "start.x=.nan"}) {
    EXPECT_THROW(Scenario::Load(smoke, ParseOverrides({bad})), InputError) << bad;
  }
  EXPECT_THROW(ParseOverride("no_value="), InputError);
  EXPECT_THROW(ParseOverride("=3"), InputError);
  EXPECT_THROW(ParseOverride("a..b=3"), InputError);
  EXPECT_THROW(Scenario::Load(smoke, ParseOverrides({"trials.x=1"})), InputError) << "trials is not a map";
}

TEST(Sweep, GridsAreParsedStrictly) {
  const SweepGrid grid = ParseGrid("stack.navigation.follower.lookahead=0.4,0.6,0.8");
  EXPECT_EQ(grid.key, "stack.navigation.follower.lookahead");
  EXPECT_EQ(grid.values, (std::vector<std::string>{"0.4", "0.6", "0.8"}));
  EXPECT_THROW(ParseGrid("lookahead="), InputError);
  EXPECT_THROW(ParseGrid("lookahead=0.4,,0.8"), InputError);
  EXPECT_THROW(ParseGrid("0.4,0.8"), InputError);
}

json RunSmoke(const std::string& name, std::uint64_t seed, const std::vector<std::string>& overrides) {
  BatchOptions options;
  options.scenario_path = testing::SourcePath("scenarios/navigation/smoke.yaml");
  options.paths = {TRIMBOT_SOURCE_DIR};
  options.trials = 6;
  options.seed = seed;
  options.jobs = 2;
  options.overrides = overrides;
  options.quiet = true;
  options.out_dir = testing::TempDir("regression_" + name);
  RunBatch(options);
  std::ifstream in(options.out_dir + "/summary.json");
  return json::parse(in);
}

// Other seeds are no regression; a slower robot is one (every trial takes longer), and a batch of
// another scenario cannot be compared.
TEST(Compare, FlagsARealRegressionAndNotOtherSeeds) {
  const json baseline = RunSmoke("baseline", 1, {});
  const json reseeded = RunSmoke("reseeded", 101, {});
  const json slower = RunSmoke("slower", 1, {"stack.navigation.follower.cruise_speed=0.15"});
  EXPECT_EQ(baseline["overrides"].size(), 0u);
  EXPECT_EQ(slower["overrides"][0], "stack.navigation.follower.cruise_speed=0.15")
      << "the result says what produced it";
  const Comparison same = CompareBatches(baseline, "baseline", reseeded, "reseeded");
  EXPECT_FALSE(same.regressed) << ToMarkdown(same);
  const Comparison worse = CompareBatches(baseline, "baseline", slower, "slower");
  EXPECT_TRUE(worse.regressed) << ToMarkdown(worse);
  const auto seconds = std::find_if(worse.metrics.begin(), worse.metrics.end(),
                                    [](const MetricComparison& m) { return m.metric == "trial_seconds"; });
  ASSERT_NE(seconds, worse.metrics.end());
  EXPECT_EQ(seconds->verdict, "regressed");
  EXPECT_GT(seconds->delta_interval.low, 0.0);
  const Comparison better = CompareBatches(slower, "slower", baseline, "baseline");
  EXPECT_FALSE(better.regressed);
  json other = baseline;
  other["scenario"] = "rectangle";
  EXPECT_THROW(CompareBatches(baseline, "baseline", other, "other"), InputError);
}

// Every effect `trimbot ablate` switches off is on in the visual trial sets as written, and its
// overrides turn exactly it off; the robot's own figures are read with the scenario.
TEST(Ablate, EachEffectIsOnAsWrittenAndItsOverridesSwitchItOff) {
  const std::string rectangle = testing::SourcePath("scenarios/navigation/rectangle_visual.yaml");
  const Scenario all = Scenario::Load(rectangle);
  const auto without = [&](const std::string& name) {
    for (const auto& e : FidelityEffects()) {
      if (e.name == name) return Scenario::Load(rectangle, ParseOverrides(e.off));
    }
    ADD_FAILURE() << "no effect " << name;
    return all;
  };
  ASSERT_TRUE(all.visual_map_recipe.has_value());
  EXPECT_EQ(all.visual_map_recipe->builder, visual_localization::KeyframePoses::kOdometry);
  EXPECT_EQ(without("map_from_log").visual_map_recipe->builder, visual_localization::KeyframePoses::kSurveyed);
  EXPECT_GT(all.setting.conditions.wind.mean_speed, 0.0);
  EXPECT_EQ(without("wind").setting.conditions.wind.mean_speed, 0.0);
  EXPECT_GT(all.setting.conditions.clouds.cover, 0.0);
  EXPECT_EQ(without("clouds").setting.conditions.clouds.cover, 0.0);
  EXPECT_EQ(without("clouds").setting.conditions.wind.mean_speed, all.setting.conditions.wind.mean_speed);
  EXPECT_TRUE(all.motion_blur);
  EXPECT_FALSE(without("motion_blur").motion_blur);
  EXPECT_GT(all.calibration_error.rotation_deg, 0.0);
  EXPECT_GT(all.calibration_error.camera_imu_time_offset_s, 0.0);
  const CalibrationError exact = without("calibration_error").calibration_error;
  EXPECT_EQ(exact.focal_relative + exact.principal_point_px + exact.rotation_deg + exact.translation_m +
                exact.camera_imu_time_offset_s,
            0.0);
  EXPECT_EQ(without("calibration_error").visual_map_recipe->calibration_error.rotation_deg, 0.0)
      << "the map is built with the calibration the robot reads";
  ASSERT_TRUE(all.robot_reference.has_value());
  EXPECT_EQ(all.robot_reference->metrics.at(1),
            (std::pair<std::string, double>{"pose_fixes_position_error_mean_m", 0.0837}));  // D3.4 Table 3
  EXPECT_THROW(Scenario::Load(rectangle, ParseOverrides({"robot_reference.metrics.speeed=1"})), InputError);
  EXPECT_THROW(Scenario::Load(rectangle, ParseOverrides({"robot_reference.source=[]"})), InputError);
}

// A summary of six trials whose visual fixes are off by `fix_m` (+ i mm in trial i).
json SyntheticSummary(double fix_m) {
  json summary{{"scenario", "rectangle_visual"}, {"trials_planned", 6}};
  std::vector<double> pooled;
  for (int i = 0; i < 6; ++i) {
    const std::vector<double> errors = {fix_m + 1e-3 * i, fix_m + 1e-3 * i};
    pooled.insert(pooled.end(), errors.begin(), errors.end());
    summary["trials"].push_back({{"success", true},
                                 {"simulated_seconds", 100.0},
                                 {"localization_rate", 1.0},
                                 {"estimates", json::array({{{"name", "pose_fixes"}, {"position_m", errors}}})}});
  }
  summary["metrics"] = {{"pose_fixes_position_error_mean_m", Mean(pooled)},
                        {"pose_fixes_position_error_median_m", Mean(pooled)},
                        {"localization_rate", 1.0}};
  return summary;
}

// The table sets the robot's figures beside the twin's, and marks an effect whose removal makes the
// fixes better beyond trial-to-trial noise.
TEST(Ablate, TheTableSetsTheRobotBesideTheTwinWithTheComparisonsVerdicts) {
  ScenarioAblation a;
  a.scenario = "rectangle_visual";
  a.robot = Scenario::Load(testing::SourcePath("scenarios/navigation/rectangle_visual.yaml")).robot_reference;
  a.batches.push_back({"", SyntheticSummary(0.05), nullptr, std::nullopt});
  for (const auto& [effect, fix_m] : {std::pair{"wind", 0.02}, {"clouds", 0.05}}) {
    AblationBatch b{effect, SyntheticSummary(fix_m), nullptr, std::nullopt};
    b.against_all = CompareBatches(a.batches.front().summary, "all", b.summary, effect);
    a.batches.push_back(b);
  }
  const std::string md = TwinVersusRobotMarkdown({a});
  EXPECT_NE(md.find("| the robot | 100.0 % | 8.37 / 6.37 cm | 12.24 / 10.54 cm | 92.3 % | - | 150 ms | - |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| twin, every effect on | 6/6 | 5.25 / 5.25 cm |"), std::string::npos) << md;
  EXPECT_NE(md.find("| without wind | 6/6 (=) | 2.25 / 2.25 cm **better** (p 0.0011) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| without clouds | 6/6 (=) | 5.25 / 5.25 cm (=) |"), std::string::npos) << md;
  const json j = TwinVersusRobotJson({a});
  EXPECT_EQ(j[0]["batches"].size(), 3u);
  EXPECT_EQ(j[0]["robot"]["metrics"]["ekf_position_error_mean_m"], 0.1224);
}

}  // namespace
}  // namespace trimbot::scenarios
