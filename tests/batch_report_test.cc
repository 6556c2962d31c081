// Batch results and reports: error statistics, lossless trial JSON, batch metrics over trials that
// failed or crashed, JUnit XML for CI, the trajectory and error plots, and TUM trajectory input.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "evaluation/localization_log.h"
#include "evaluation/trial_evaluator.h"
#include "evaluation/trial_result.h"
#include "reports/batch_report.h"
#include "reports/localization_timing.h"
#include "reports/run_timing.h"
#include "test_support.h"
#include "trimbot/common/input_error.h"
#include "trimbot/garden/garden_tools.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;

std::string ReadText(const std::string& path) {
  std::ifstream file(path);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

EstimateErrors Estimate(const std::string& name, std::vector<double> position_m, std::vector<double> heading_deg) {
  EstimateErrors e;
  e.name = name;
  e.position_m = std::move(position_m);
  e.heading_deg = std::move(heading_deg);
  return e;
}

GoalResult Goal(double x, double y, bool reached) {
  GoalResult g;
  g.x = x;
  g.y = y;
  g.reached = g.reached_as_asked = reached;
  g.arrival_time = reached ? 42.5 : -1.0;
  g.final_error_m = reached ? 0.12 : -1.0;
  return g;
}

TEST(ErrorStats, KnownSamples) {
  const ErrorStats odd = ErrorStats::From({3.0, 1.0, 4.0, 1.0, 5.0});
  EXPECT_EQ(odd.count, 5);
  EXPECT_DOUBLE_EQ(odd.mean, 2.8);
  EXPECT_DOUBLE_EQ(odd.median, 3.0);
  EXPECT_DOUBLE_EQ(odd.rmse, std::sqrt(52.0 / 5.0));
  EXPECT_DOUBLE_EQ(odd.max, 5.0);

  const ErrorStats even = ErrorStats::From({4.0, 1.0, 3.0, 2.0});
  EXPECT_DOUBLE_EQ(even.median, 2.5);

  const ErrorStats none = ErrorStats::From({});
  EXPECT_EQ(none.count, 0);
  EXPECT_EQ(none.mean, 0.0);
  EXPECT_EQ(none.median, 0.0);
  EXPECT_EQ(none.rmse, 0.0);
  EXPECT_EQ(none.max, 0.0);
}

void ExpectSameTrial(const TrialResult& a, const TrialResult& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.message, b.message);
  EXPECT_EQ(a.success, b.success);
  ASSERT_EQ(a.goals.size(), b.goals.size());
  for (std::size_t i = 0; i < a.goals.size(); ++i) {
    EXPECT_EQ(a.goals[i].x, b.goals[i].x);
    EXPECT_EQ(a.goals[i].y, b.goals[i].y);
    EXPECT_EQ(a.goals[i].reached, b.goals[i].reached);
    EXPECT_EQ(a.goals[i].arrival_time, b.goals[i].arrival_time);
    EXPECT_EQ(a.goals[i].final_error_m, b.goals[i].final_error_m);
  }
  EXPECT_EQ(a.simulated_seconds, b.simulated_seconds);
  EXPECT_EQ(b.wall_seconds, 0.0) << "wall-clock time stays out of result.json (it is not reproducible)";
  EXPECT_EQ(a.path_length_m, b.path_length_m);
  EXPECT_EQ(a.collisions, b.collisions);
  EXPECT_EQ(a.contact_seconds, b.contact_seconds);
  EXPECT_EQ(a.replans, b.replans);
  EXPECT_EQ(a.recoveries, b.recoveries);
  EXPECT_EQ(a.fixes_accepted, b.fixes_accepted);
  EXPECT_EQ(a.fixes_rejected, b.fixes_rejected);
  EXPECT_EQ(a.relocalizations, b.relocalizations);
  EXPECT_EQ(a.visual_frames_attempted, b.visual_frames_attempted);
  EXPECT_EQ(a.faults, b.faults);
  ASSERT_EQ(a.estimates.size(), b.estimates.size());
  for (std::size_t i = 0; i < a.estimates.size(); ++i) {
    EXPECT_EQ(a.estimates[i].name, b.estimates[i].name);
    EXPECT_EQ(a.estimates[i].position_m, b.estimates[i].position_m);  // exact: doubles must survive the text
    EXPECT_EQ(a.estimates[i].heading_deg, b.estimates[i].heading_deg);
    EXPECT_EQ(a.estimates[i].nees, b.estimates[i].nees);
  }
}

TEST(TrialResultJson, RoundTripIsLossless) {
  TrialResult trial;
  trial.index = 17;
  trial.seed = std::numeric_limits<std::uint64_t>::max() - 5;  // beyond a double's exact integers
  trial.status = "timeout";
  trial.message = "goal 2 \"hedge corner\" not reached\nafter 300 s";
  trial.success = false;
  trial.goals = {Goal(1.0 / 3.0, -2.7, true), Goal(6.02e-3, 1e300, false)};
  trial.simulated_seconds = 300.00000000000006;
  trial.wall_seconds = 71.123456789;
  trial.path_length_m = 12.3;
  trial.collisions = 2;
  trial.contact_seconds = 0.35;
  trial.replans = 4;
  trial.recoveries = 1;
  trial.fixes_accepted = 40;
  trial.fixes_rejected = 3;
  trial.relocalizations = 1;
  trial.visual_frames_attempted = 57;
  trial.visual_frame_outcomes = {{"accepted", 50}, {"no pose: matching", 7}};
  trial.localization_stopped_updates = 12;
  trial.faults = {"camera 3 dropped at 20 s", "wheel slip 10 %"};
  trial.estimates = {Estimate("ekf", {0.1, 0.2, 1e-17, 0.30000000000000004}, {0.5, 179.9}),
                     Estimate("pose_fixes", {}, {})};
  trial.estimates[0].nees = {2.5, 1e-9, 31.0};

  const nlohmann::json written = trial;
  // Through text, as the file is written and read.
  const TrialResult read = nlohmann::json::parse(written.dump()).get<TrialResult>();
  ExpectSameTrial(trial, read);

  // Summaries are written beside the samples for readers of the file.
  const auto& ekf = written["estimates"][0];
  EXPECT_EQ(ekf["position_stats_m"]["count"], 4);
  EXPECT_NEAR(ekf["position_stats_m"]["max"].get<double>(), 0.30000000000000004, 1e-15);
  EXPECT_DOUBLE_EQ(ekf["heading_stats_deg"]["mean"].get<double>(), 90.2);
}

// One successful trial, one that failed on its second goal, one that crashed before any result.
std::vector<TrialResult> ThreeTrials() {
  TrialResult good;
  good.index = 0;
  good.status = "completed";
  good.success = true;
  good.goals = {Goal(1, 1, true), Goal(2, 2, true)};
  good.goals[1].adjusted_by_m = 0.5;  // reached where the robot moved it, 0.5 m from the goal as asked
  good.goals[1].reached_as_asked = false;
  good.simulated_seconds = 100.0;
  good.wall_seconds = 10.0;
  good.path_length_m = 20.0;
  good.recoveries = 1;
  good.estimates = {Estimate("ekf", {0.1, 0.2, 0.3}, {1.0, 2.0, 3.0}), Estimate("wheel_odometry", {0.5, 1.0}, {5.0})};

  TrialResult failed;
  failed.index = 1;
  failed.status = "failed";
  failed.message = "goal 2 not reached";
  failed.goals = {Goal(1, 1, true), Goal(2, 2, false)};
  failed.simulated_seconds = 200.0;
  failed.wall_seconds = 20.0;
  failed.path_length_m = 10.0;
  failed.collisions = 2;
  failed.recoveries = 2;
  failed.estimates = {Estimate("ekf", {0.5, 0.4}, {10.0, 4.0})};

  TrialResult crashed;
  crashed.index = 2;
  crashed.status = "crashed";
  crashed.message = "signal 11";
  crashed.wall_seconds = 1.0;
  return {good, failed, crashed};
}

TEST(BatchMetrics, RatesMeansAndPooledErrors) {
  const nlohmann::json m = ComputeBatchMetrics(ThreeTrials(), 3);
  EXPECT_DOUBLE_EQ(m["success_rate"].get<double>(), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(m["goal_success_rate"].get<double>(), 3.0 / 6.0);           // the crashed trial's 2 goals count
  EXPECT_DOUBLE_EQ(m["goal_success_rate_as_asked"].get<double>(), 2.0 / 6.0);  // one was moved
  EXPECT_EQ(m["trials_completed"], 1);
  EXPECT_EQ(m["collisions"], 2);
  EXPECT_EQ(m["recoveries"], 3);
  EXPECT_DOUBLE_EQ(m["mean_trial_seconds"].get<double>(), 100.0);
  EXPECT_FALSE(m.contains("mean_wall_seconds")) << "wall-clock time stays out of summary.json";
  EXPECT_DOUBLE_EQ(m["mean_path_length_m"].get<double>(), 10.0);

  // ekf pooled over two trials: 0.1 .. 0.5 m and 1, 2, 3, 4, 10 degrees.
  EXPECT_DOUBLE_EQ(m["ekf_position_error_median_m"].get<double>(), 0.3);
  EXPECT_DOUBLE_EQ(m["ekf_position_error_mean_m"].get<double>(), 0.3);
  EXPECT_DOUBLE_EQ(m["ekf_position_error_max_m"].get<double>(), 0.5);
  EXPECT_NEAR(m["ekf_position_error_rmse_m"].get<double>(), std::sqrt(0.11), 1e-12);
  EXPECT_DOUBLE_EQ(m["ekf_heading_error_median_deg"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(m["ekf_heading_error_mean_deg"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(m["ekf_heading_error_max_deg"].get<double>(), 10.0);
  EXPECT_DOUBLE_EQ(m["wheel_odometry_position_error_median_m"].get<double>(), 0.75);
  EXPECT_DOUBLE_EQ(m["wheel_odometry_heading_error_median_deg"].get<double>(), 5.0);
  EXPECT_FALSE(m.contains("pose_fixes_position_error_mean_m"));  // no trial had it
  EXPECT_EQ(m.size(), 8u + 2u * 7u);

  // A planned trial that never ran counts as failed.
  const nlohmann::json four = ComputeBatchMetrics(ThreeTrials(), 4);
  EXPECT_DOUBLE_EQ(four["success_rate"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(four["goal_success_rate"].get<double>(), 3.0 / 8.0);
}

// Per-frame success of the stack's visual localization: fixes the EKF accepted over the frames the
// localizer attempted, pooled over the trials it ran in; a trial with the simulated fixture (no
// frames attempted) counts in neither.
TEST(BatchMetrics, VisualFrameSuccessIsPooledOverTheTrialsThatLocalized) {
  std::vector<TrialResult> trials(3);
  trials[0].visual_frames_attempted = 100;
  trials[0].fixes_accepted = 80;
  trials[0].simulated_seconds = 50.0;
  trials[1].visual_frames_attempted = 60;
  trials[1].fixes_accepted = 30;
  trials[1].simulated_seconds = 30.0;
  trials[2].fixes_accepted = 500;  // the simulated_pose_fixes fixture
  trials[2].simulated_seconds = 100.0;
  const nlohmann::json m = ComputeBatchMetrics(trials, 3);
  EXPECT_DOUBLE_EQ(m["visual_frame_success_rate"].get<double>(), 110.0 / 160.0);
  EXPECT_DOUBLE_EQ(m["visual_frame_rate_hz"].get<double>(), 160.0 / 80.0);
  EXPECT_FALSE(ComputeBatchMetrics(ThreeTrials(), 3).contains("visual_frame_success_rate"));
}

// The EKF's consistency, pooled over trials: the mean NEES, and the share of samples below the 95 %
// quantile of chi-square with 3 dof; estimates without NEES samples have neither.
TEST(BatchMetrics, NeesIsPooledOverTrials) {
  std::vector<TrialResult> trials(2);
  trials[0].estimates = {Estimate("ekf", {0.1, 0.1}, {1.0, 1.0}), Estimate("wheel_odometry", {0.2}, {2.0})};
  trials[0].estimates[0].nees = {1.0, 2.0};
  trials[1].estimates = {Estimate("ekf", {0.1, 0.1}, {1.0, 1.0})};
  trials[1].estimates[0].nees = {9.0, 4.0};
  const nlohmann::json m = ComputeBatchMetrics(trials, 2);
  EXPECT_DOUBLE_EQ(m["ekf_nees_mean"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(m["ekf_nees_within_95_rate"].get<double>(), 0.75);  // 9 > 7.81
  EXPECT_FALSE(m.contains("wheel_odometry_nees_mean"));
}

BatchSummary SummaryWithTwoGoodTrials() {
  BatchSummary summary;
  summary.scenario = "lawn <A&B>";
  summary.scenario_file = "scenarios/lawn.yaml";
  summary.seed = 7;
  summary.trials_planned = 2;
  for (int i = 0; i < 2; ++i) {
    TrialResult trial;
    trial.index = 7 + i;
    trial.seed = 42 + i;
    trial.status = "completed";
    trial.success = true;
    trial.wall_seconds = 1.25;
    summary.trials.push_back(trial);
  }
  summary.criteria = {{"success_rate", ">=", 1.0, 0.5, false}, {"ekf_position_error_median_m", "<=", 0.1, 0.05, true}};
  return summary;
}

TEST(JunitXml, CountsTheFailingCriterionAndEscapesNames) {
  const std::string path = testing::TempDir("batch_report") + "/junit_criterion.xml";
  WriteJunitXml(path, SummaryWithTwoGoodTrials());
  const std::string xml = ReadText(path);
  EXPECT_NE(xml.find("<testsuite name=\"lawn &lt;A&amp;B&gt;\" tests=\"4\" failures=\"1\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("time=\"2.500\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("classname=\"lawn &lt;A&amp;B&gt;.criteria\" name=\"success_rate &gt;= 1\""), std::string::npos)
      << xml;
  EXPECT_NE(xml.find("<failure message=\"expected success_rate &gt;= 1, actual 0.5\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("name=\"ekf_position_error_median_m &lt;= 0.1\" time=\"0\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("classname=\"lawn &lt;A&amp;B&gt;.trials\" name=\"trial 007 seed 42\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("name=\"trial 008 seed 43\""), std::string::npos) << xml;
  EXPECT_EQ(xml.find("<A&B>"), std::string::npos) << "unescaped name in\n" << xml;
}

TEST(JunitXml, FailedTrialCarriesStatusAndMessage) {
  BatchSummary summary = SummaryWithTwoGoodTrials();
  summary.criteria.clear();
  summary.trials[1].success = false;
  summary.trials[1].status = "crashed";
  summary.trials[1].message = "segfault in \"planner\" <x>";
  const std::string path = testing::TempDir("batch_report") + "/junit_trial.xml";
  WriteJunitXml(path, summary);
  const std::string xml = ReadText(path);
  EXPECT_NE(xml.find("tests=\"2\" failures=\"1\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<failure message=\"crashed: segfault in &quot;planner&quot; &lt;x&gt;\""), std::string::npos)
      << xml;
}

// A 10 m x 5 m map at 5 cm with a 1 m square obstacle, origin at (-2, -1).
garden::OccupancyMap TestMap() {
  cv::Mat occupied(100, 200, CV_8U, cv::Scalar(0));
  // Obstacle over x in [3, 4], y in [2.5, 3.5]: columns (x + 2) / 0.05, rows from the top.
  occupied(cv::Rect(100, 10, 20, 20)).setTo(255);
  garden::OccupancyMap map;
  map.occupied = occupied;
  map.resolution = 0.05;
  map.origin = Eigen::Vector2d(-2.0, -1.0);
  return map;
}

std::vector<Eigen::Vector2d> Line(const Eigen::Vector2d& from, const Eigen::Vector2d& to, int points) {
  std::vector<Eigen::Vector2d> line;
  for (int i = 0; i < points; ++i) line.push_back(from + (to - from) * i / (points - 1.0));
  return line;
}

bool Saturated(const cv::Vec3b& bgr, int min_spread) {
  return std::max({bgr[0], bgr[1], bgr[2]}) - std::min({bgr[0], bgr[1], bgr[2]}) >= min_spread;
}

// Whether any pixel within `radius` of `centre` passes `test`.
template <typename Test>
bool AnyNear(const cv::Mat& image, cv::Point centre, int radius, Test test) {
  for (int dy = -radius; dy <= radius; ++dy) {
    for (int dx = -radius; dx <= radius; ++dx) {
      const cv::Point p = centre + cv::Point(dx, dy);
      if (p.inside(cv::Rect(0, 0, image.cols, image.rows)) && test(image.at<cv::Vec3b>(p))) return true;
    }
  }
  return false;
}

TEST(TrajectoryPlot, DrawsMapTrajectoriesAndGoals) {
  const garden::OccupancyMap map = TestMap();
  PlotTrajectory good;
  good.trial = 0;
  good.success = true;
  good.ground_truth = Line({0.0, 0.0}, {6.0, 2.0}, 50);
  good.estimate = Line({0.0, 0.05}, {6.1, 2.1}, 50);
  PlotTrajectory failed;
  failed.trial = 1;
  failed.success = false;
  failed.ground_truth = Line({0.0, -0.5}, {5.0, -0.5}, 30);
  failed.estimate = Line({0.0, -0.45}, {4.8, -0.3}, 30);
  const std::string path = testing::TempDir("batch_report") + "/trajectories.png";
  fs::remove(path);
  // The world has one more obstacle than the map: x in [0, 0.5], y in [2.5, 3.0].
  garden::OccupancyMap world = map;
  world.occupied = map.occupied.clone();
  world.occupied(cv::Rect(40, 20, 10, 10)).setTo(255);
  WriteTrajectoryPlot(path, map, world, {good, failed}, {{6.0, 2.0}, {7.0, 0.5}}, "lawn: 2 trials, seed 7");
  std::cout << "trajectory plot: " << path << "\n";

  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);  // BGR
  ASSERT_FALSE(image.empty()) << path;
  EXPECT_EQ(image.cols, 1200);
  // 10 m over 1200 px: 120 px/m, so the 5 m map is 600 px tall, plus the title and legend.
  EXPECT_GT(image.rows, 600 + 40);
  EXPECT_LT(image.rows, 600 + 400);

  // The map's frame runs down the right edge: its first row is the map's top (y = 4 m).
  int map_top = 0;
  while (map_top < image.rows && image.at<cv::Vec3b>(map_top, image.cols - 1) == cv::Vec3b(255, 255, 255)) ++map_top;
  ASSERT_LT(map_top, 100);
  const auto pixel = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround((x + 2.0) * 120.0)),
                     map_top + static_cast<int>(std::lround((4.0 - y) * 120.0)));
  };
  // Trajectories: coloured where they pass; the failed one red-ish.
  EXPECT_TRUE(AnyNear(image, pixel(3.0, 1.0), 2, [](const cv::Vec3b& bgr) { return Saturated(bgr, 80); }));
  EXPECT_TRUE(AnyNear(image, pixel(2.5, -0.5), 2, [](const cv::Vec3b& bgr) {
    return bgr[2] > 150 && bgr[2] > bgr[1] + 80 && bgr[2] > bgr[0] + 80;
  }));
  // Free space away from everything is light and grey; the obstacle is dark grey.
  const cv::Vec3b free = image.at<cv::Vec3b>(pixel(-1.3, 3.3));
  EXPECT_GT(free[1], 200);
  EXPECT_FALSE(Saturated(free, 20));
  const cv::Vec3b obstacle = image.at<cv::Vec3b>(pixel(3.5, 3.0));
  EXPECT_LT(obstacle[1], 130);
  EXPECT_FALSE(Saturated(obstacle, 20));
  // The obstacle the map lacks: orange.
  const cv::Vec3b unmapped = image.at<cv::Vec3b>(pixel(0.25, 2.75));
  EXPECT_GT(unmapped[2], 180);
  EXPECT_LT(unmapped[0], 110);
  // Goal 2 is a white circle with a dark outline and number.
  EXPECT_TRUE(AnyNear(image, pixel(7.0, 0.5), 6, [](const cv::Vec3b& bgr) { return bgr[1] < 100; }));
}

// The localization log is read back frame by frame (a frame without truth has no position), and the
// map puts each frame at its position in its outcome's colour: accepted green, no pose orange,
// rejected red.
TEST(LocalizationMapPlot, FramesAtTheirTruePositionsInTheirOutcomesColours) {
  const std::string dir = testing::TempDir("batch_report");
  const std::string csv = dir + "/localization.csv";
  {
    std::ofstream out(csv);
    out << "t,true_x,true_y,true_yaw,outcome,failure,features,matches,inliers,error_m,sigma_m,nees\n"
        << "0.2,1.0,1.0,0.0,accepted,\"\",900,300,200,0.01,0.02,0.3\n"
        << "0.8,3.0,1.0,0.0,no pose: pose,\"RANSAC found 4 inliers, 12 needed\",900,90,0,,,\n"
        << "1.4,5.0,1.0,0.0,rejected as an outlier,\"\",900,60,20,2.1,0.02,9000\n"
        << "2.0,,,,pending,\"\",900,300,200,,,\n";
  }
  const std::vector<LocalizationFrame> frames = ReadLocalizationCsv(csv);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[1].outcome, "no pose: pose");
  EXPECT_EQ(frames[2].position, Eigen::Vector2d(5.0, 1.0));
  EXPECT_FALSE(frames[3].position.allFinite());
  const std::string path = dir + "/localization_map.png";
  fs::remove(path);
  const garden::OccupancyMap map = TestMap();
  WriteLocalizationMap(path, map, map, frames, "lawn: where localization broke");
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);  // BGR
  ASSERT_FALSE(image.empty()) << path;
  int map_top = 0;
  while (map_top < image.rows && image.at<cv::Vec3b>(map_top, image.cols - 1) == cv::Vec3b(255, 255, 255)) ++map_top;
  const auto pixel = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround((x + 2.0) * 120.0)),
                     map_top + static_cast<int>(std::lround((4.0 - y) * 120.0)));
  };
  const cv::Vec3b accepted = image.at<cv::Vec3b>(pixel(1.0, 1.0)), no_pose = image.at<cv::Vec3b>(pixel(3.0, 1.0)),
                  rejected = image.at<cv::Vec3b>(pixel(5.0, 1.0));
  EXPECT_TRUE(accepted[1] > accepted[0] + 60 && accepted[1] > accepted[2] + 60) << accepted;
  EXPECT_TRUE(no_pose[2] > 200 && no_pose[1] > 100 && no_pose[0] < 80) << no_pose;
  EXPECT_TRUE(rejected[2] > 150 && rejected[1] < 80) << rejected;
  const std::string bad = testing::WriteTempFile("localization_bad.csv", "t,true_x\n0.2,1.0\n");
  EXPECT_THROW(ReadLocalizationCsv(bad), InputError);
}

TrialResult TrialWithErrors(int index, double scale_m) {
  TrialResult trial;
  trial.index = index;
  std::vector<double> ekf, fixes;
  for (int i = 0; i < 500; ++i) {
    ekf.push_back(scale_m * (0.2 + std::abs(std::sin(i * 0.37))));
    fixes.push_back(0.5 * scale_m * (0.1 + std::abs(std::cos(i * 0.11))));
  }
  fixes.push_back(3.0);  // an outlier beyond the histogram's range
  trial.estimates = {Estimate("ekf", ekf, {}), Estimate("pose_fixes", fixes, {})};
  return trial;
}

TEST(ErrorHistograms, OnePanelPerEstimateWithBars) {
  const std::string path = testing::TempDir("batch_report") + "/errors.png";
  fs::remove(path);
  WriteErrorHistograms(path, {TrialWithErrors(0, 0.1), TrialWithErrors(1, 0.15)}, "lawn: localization error");
  std::cout << "error histograms: " << path << "\n";

  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty()) << path;
  // Two panels side by side, 600 x 420 each, under a 50 px title.
  EXPECT_EQ(image.cols, 2 * 600);
  EXPECT_EQ(image.rows, 50 + 420);
  // Both panels have bars (blue fill).
  const auto bar_pixels = [&](int first_column) {
    int count = 0;
    for (int r = 0; r < image.rows; ++r) {
      for (int c = first_column; c < first_column + 600; ++c) {
        const cv::Vec3b bgr = image.at<cv::Vec3b>(r, c);
        count += bgr[0] > bgr[2] + 60 ? 1 : 0;
      }
    }
    return count;
  };
  EXPECT_GT(bar_pixels(0), 2000);
  EXPECT_GT(bar_pixels(600), 2000);

  // No trials: a picture that says so rather than an error.
  const std::string empty_path = testing::TempDir("batch_report") + "/errors_empty.png";
  WriteErrorHistograms(empty_path, {}, "no trials");
  EXPECT_FALSE(cv::imread(empty_path).empty());
}

TEST(ReadTumPositions, ReadsPositionsAndNamesTheBadLine) {
  const std::string good = testing::WriteTempFile("good.tum",
                                                  "# t x y z qx qy qz qw\n"
                                                  "0.0 1.5 -2.0 0.1 0 0 0 1\n"
                                                  "\n"
                                                  "0.1 1.6 -2.1 0.1 0 0 0.0998 0.995\r\n");
  const auto positions = ReadTumPositions(good);
  ASSERT_EQ(positions.size(), 2u);
  EXPECT_EQ(positions[0], Eigen::Vector2d(1.5, -2.0));
  EXPECT_EQ(positions[1], Eigen::Vector2d(1.6, -2.1));

  const std::string bad = testing::WriteTempFile("bad.tum",
                                                 "# t x y z qx qy qz qw\n"
                                                 "0.0 1.5 -2.0 0.1 0 0 0 1\n"
                                                 "\n"
                                                 "0.1 1.6 oops 0.1 0 0 0 1\n");
  try {
    ReadTumPositions(bad);
    FAIL() << "no InputError for " << bad;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), bad);
    EXPECT_NE(std::string(e.what()).find("bad.tum: line 4:"), std::string::npos) << e.what();
  }
  const std::string short_line = testing::WriteTempFile("short.tum", "0.0 1.5 -2.0\n");
  EXPECT_THROW(ReadTumPositions(short_line), InputError);
  EXPECT_THROW(ReadTumPositions("/nonexistent/trajectory.tum"), InputError);
}

// Per-frame stage times: median and p90 of each stage and of the total, the frames round-tripped
// through the JSON (0.1 ms), and the Figure 10 histogram drawn.
TEST(LocalizationTiming, StatsPerStageAndTheHistogram) {
  std::vector<visual_localization::LocalizationTimings> frames;
  for (int i = 1; i <= 10; ++i) frames.push_back({0.010 * i, 0.001, 0.002 * i, 0.0005});
  const nlohmann::json stats = LocalizationTimeStats(frames);
  EXPECT_EQ(stats["frames"].get<int>(), 10);
  EXPECT_NEAR(stats["features"]["median_ms"].get<double>(), 55.0, 1e-9);           // between 50 and 60
  EXPECT_NEAR(stats["features"]["p90_ms"].get<double>(), 91.0, 1e-9);              // 90 + 0.1 * 10
  EXPECT_NEAR(stats["total"]["median_ms"].get<double>(), 12.0 * 5.5 + 1.5, 1e-9);  // frame i: 12 i + 1.5 ms
  EXPECT_NEAR(stats["total"]["max_ms"].get<double>(), 121.5, 1e-9);
  const auto back = LocalizationTimesFromJson(stats);
  ASSERT_EQ(back.size(), frames.size());
  EXPECT_NEAR(back[9].matching, 0.020, 1e-6);
  const std::string path = testing::TempDir("localization_timing") + "/localization_time.png";
  WriteLocalizationTimeHistogram(path, "test", frames);
  const cv::Mat image = cv::imread(path);
  ASSERT_FALSE(image.empty());
  EXPECT_GT(image.cols, 600);
}

// The run's time by stage: every stage's seconds as measured, "other" the rest of the wall time,
// per-item figures where counted; the JSON reads back; trials add up; the chart is written.
TEST(RunTiming, StagesAccountForTheWallTimeAndAddUpOverTrials) {
  sim::SimulatorTimings sim;
  sim.physics = 2.0;
  sim.physics_steps = 4000;
  sim.render_draw = 10.0;
  sim.camera_images = 200;
  sim.exposure_noise = 0.5;
  stack::StackTimings stack;
  stack.ekf = 0.25;
  stack.visual_localization = 4.5;
  stack.visual_frames = {{0.06, 0.005, 0.02, 0.005}, {0.07, 0.005, 0.02, 0.005}};
  stack.planning = 0.5;
  const RunTiming run = MakeRunTiming(25.0, 10.0, sim, &stack, 1.0, 0.25);
  double sum = 0.0;
  const StageTime* other = nullptr;
  const StageTime* draw = nullptr;
  const StageTime* features = nullptr;
  for (const auto& s : run.stages) {
    sum += s.seconds;
    if (s.name == "other") other = &s;
    if (s.name == "render_draw") draw = &s;
    if (s.name == "visual_features") features = &s;
  }
  ASSERT_NE(other, nullptr);
  ASSERT_NE(draw, nullptr);
  ASSERT_NE(features, nullptr);
  EXPECT_EQ(run.stages.back().name, "other");
  EXPECT_NEAR(sum, 25.0, 1e-9);
  EXPECT_NEAR(features->seconds, 0.13, 1e-12);
  EXPECT_EQ(features->count, 2);
  const nlohmann::json json = ToJson(run);
  EXPECT_NEAR(json["real_time_factor"].get<double>(), 0.4, 1e-12);
  EXPECT_NEAR(json["stages"][1]["ms_per"].get<double>(), 50.0, 1e-9);  // render_draw per camera image
  const RunTiming back = RunTimingFromJson(json);
  ASSERT_EQ(back.stages.size(), run.stages.size());
  const RunTiming two = Sum({run, back});
  EXPECT_NEAR(two.wall_seconds, 50.0, 1e-9);
  EXPECT_NEAR(two.stages[1].seconds, 20.0, 1e-9);
  EXPECT_EQ(two.stages[1].count, 400);
  EXPECT_EQ(two.stages.back().name, "other");
  EXPECT_THROW(RunTimingFromJson(nlohmann::json{{"wall_seconds", 1.0}}), std::runtime_error);
  const std::string png = testing::TempDir("run_timing") + "/timing.png";
  WriteRunTimingChart(png, "test", run);
  EXPECT_FALSE(cv::imread(png).empty());
  EXPECT_NE(FormatRunTiming(run).find("render_draw"), std::string::npos);
}

// Clearance is measured with the base's outline at the true pose against the garden as it is:
// positive before an obstacle, negative as deep as the outline reaches into it.
// Every frame the localizer tried is logged at its true pose with what came of it: no pose (the
// stage), or the fix's error, stated sigma and NEES with the EKF's verdict; a fix that never
// arrived stays pending.
TEST(LocalizationLog, EachFrameWithItsOutcomeErrorAndConsistency) {
  LocalizationLog log;
  const TruePose truth{1.0, 2.0, 0.5};
  stack::LocalizationAttempt failed{
      10.0, visual_localization::FailedStage::kPose, "RANSAC found 12 inliers, 20 needed", 900, 60, 0};
  stack::LocalizationAttempt localized{10.6, visual_localization::FailedStage::kNone, "", 1000, 300, 200};
  stack::LocalizationAttempt late{11.2, visual_localization::FailedStage::kNone, "", 1000, 280, 190};
  log.AddAttempt(failed, &truth);
  log.AddAttempt(localized, &truth);
  log.AddAttempt(late, &truth);
  stack::AppliedFix fix;
  fix.fix.stamp = 10.6;
  fix.fix.x = 1.03;  // 3 cm off along x, at a stated 2 cm: NEES (3/2)^2 = 2.25
  fix.fix.y = 2.0;
  fix.fix.yaw = 0.5;
  fix.fix.covariance = Eigen::Vector3d(0.02 * 0.02, 0.01 * 0.01, 0.01 * 0.01).asDiagonal();
  fix.outcome = stack::FixOutcome::kRejectedOutlier;
  log.AddFix(fix, &truth);
  const auto outcomes = log.Outcomes();
  EXPECT_EQ(outcomes.at("no pose: pose"), 1);
  EXPECT_EQ(outcomes.at("rejected as an outlier"), 1);
  EXPECT_EQ(outcomes.at("pending"), 1);
  const std::string csv = log.Csv();
  EXPECT_NE(csv.find("10.000,1.000,2.000,0.5000,no pose: pose,\"RANSAC found 12 inliers, 20 needed\",900,60,0,,,\n"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find("10.600,1.000,2.000,0.5000,rejected as an outlier,\"\",1000,300,200,0.0300,0.0200,2.250\n"),
            std::string::npos)
      << csv;
}

// Exact to the millimetre against the footprints, not a map's cells: a box the base drives at and
// a round bush beside it; a crown above the base's top is no obstacle.
TEST(TrialEvaluator, MeasuresClearanceOfTheBaseOutline) {
  garden::Garden world;
  garden::GardenObject box;  // x 2.0..2.5, y -0.5..0.5
  box.id = 1;
  box.position = {2.25, 0.0};
  box.size = {0.5, 1.0, 1.0};
  garden::GardenObject bush = box;  // a cylinder of radius 0.3 centred 1 m to the robot's left
  bush.id = 2;
  bush.shape = garden::Shape::kCylinder;
  bush.position = {0.0, 1.0};
  bush.size = {0.6, 0.6, 1.0};
  garden::GardenObject crown = bush;  // a crown above the robot's top, right over it
  crown.id = 3;
  crown.shape = garden::Shape::kEllipsoid;
  crown.position = {1.0, 0.0};
  crown.base_height = 0.8;
  world.objects = {box, bush, crown};
  const auto clearance_at = [&](double x, double yaw) {
    TrialEvaluator evaluator({}, GoalCriteria{}, 1.0);
    evaluator.MeasureClearance(world, 0.6, {-0.12, -0.235}, {0.58, 0.235});
    sim::SensorOutputs sensors;
    std::vector<messages::PoseFix> fixes;
    sim::GroundTruth truth;
    truth.T_map_base.translation() = Eigen::Vector3d(x, 0.0, 0.0);
    truth.T_map_base.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    messages::RobotCommands commands;
    stack::Telemetry telemetry;
    evaluator.Observe({0.1, 0.1, sensors, fixes, truth, commands, &telemetry});
    TrialResult result;
    evaluator.Finish(true, 10.0, telemetry, &result);
    return result.min_clearance_m.value_or(std::numeric_limits<double>::quiet_NaN());
  };
  EXPECT_NEAR(clearance_at(1.2, 0.0), 2.0 - 1.78, 0.001) << "the outline's front at 1.78 m";
  EXPECT_NEAR(clearance_at(1.6, 0.0), 2.0 - 2.18, 0.001) << "0.18 m into the box";
  EXPECT_NEAR(clearance_at(0.0, 0.0), 1.0 - 0.3 - 0.235, 0.001) << "the bush beside the base";
  // Turned a quarter to the left, the base's front (0.58 m) points at the bush.
  EXPECT_NEAR(clearance_at(0.0, M_PI / 2), 1.0 - 0.3 - 0.58, 0.001) << "the bush ahead";
}

}  // namespace
}  // namespace trimbot::scenarios
