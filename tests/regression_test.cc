// Statistics of batch comparison, command-line overrides, and the regression check itself.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "evaluation/comparison.h"
#include "evaluation/statistics.h"
#include "loop/scenario.h"
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

}  // namespace
}  // namespace trimbot::scenarios
