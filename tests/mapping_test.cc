// Visual maps: the file round-trips, bad or foreign files are refused with the file named, and a
// short mapping drive gives a consistent map.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <regex>

#include "loop/closed_loop.h"
#include "loop/drive_plan.h"
#include "loop/pilots.h"
#include "loop/prior_knowledge.h"
#include "loop/scenario.h"
#include "reports/batch_report.h"
#include "runners/drive.h"
#include "runners/localization_eval.h"
#include "runners/map_cache.h"
#include "runners/mapping.h"
#include "test_support.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/garden/textures.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/stack/robot_stack.h"
#include "trimbot/stack/stack_parameters.h"
#include "trimbot/visual_localization/localizer.h"
#include "trimbot/visual_localization/visual_map.h"

namespace trimbot::visual_localization {
namespace {

VisualMap SmallMap() {
  VisualMap map;
  map.garden = "test_lawn";
  map.rig_signature = "0123456789abcdef";
  for (int k = 0; k < 3; ++k) {
    MapKeyframe keyframe;
    keyframe.id = k;
    keyframe.stamp = 0.2 * k;
    keyframe.T_map_base.translation() << 0.3 * k, -0.1, 0.0;
    keyframe.T_map_base.linear() = Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    map.keyframes.push_back(keyframe);
  }
  map.descriptors = cv::Mat(5, 128, CV_32F);
  cv::randu(map.descriptors, 0.0, 200.0);
  for (int i = 0; i < 5; ++i) {
    map.points.emplace_back(i, 2.0 * i, 0.5);
    map.observations.push_back({i % 3, i, i, Eigen::Vector2d(100.5 + i, 200.25)});
  }
  map.vocabulary = map.descriptors.rowRange(0, 2).clone();
  map.builder = "log";
  map.appearance_version = 3;
  return map;
}

TEST(VisualMap, RoundTripsThroughItsFile) {
  const VisualMap map = SmallMap();
  const std::string path = testing::TempDir("visual_map") + "/map.sqlite";
  map.Save(path);
  const VisualMap read = VisualMap::Load(path, "test_lawn", "0123456789abcdef");
  ASSERT_EQ(read.keyframes.size(), 3u);
  EXPECT_TRUE(read.keyframes[2].T_map_base.isApprox(map.keyframes[2].T_map_base, 1e-12));
  EXPECT_EQ(read.keyframes[1].stamp, 0.2);
  ASSERT_EQ(read.points.size(), 5u);
  EXPECT_EQ(read.points[4], map.points[4]);
  EXPECT_EQ(cv::norm(read.descriptors, map.descriptors, cv::NORM_INF), 0.0);
  ASSERT_EQ(read.observations.size(), 5u);
  EXPECT_EQ(read.observations[3].pixel, map.observations[3].pixel);
  EXPECT_EQ(read.observations[3].camera, 3);
  EXPECT_EQ(cv::norm(read.vocabulary, map.vocabulary, cv::NORM_INF), 0.0);
  EXPECT_EQ(read.descriptor, map.descriptor);
  EXPECT_EQ(read.builder, "log");
  EXPECT_EQ(read.appearance_version, 3);
}

// A map file a scenario names must show the garden as this build renders it (the texture
// generator's version): an older one is refused naming the file, the current one accepted.
TEST(VisualMap, AMapOfAnotherGardenAppearanceIsRefused) {
  const std::string dir = testing::TempDir("visual_map_appearance");
  VisualMap map = SmallMap();
  map.appearance_version = garden::kTextureGeneratorVersion - 1;
  map.Save(dir + "/old.sqlite");
  map.appearance_version = garden::kTextureGeneratorVersion;
  map.Save(dir + "/current.sqlite");
  const auto scenario_with = [&](const std::string& map_file) {
    return scenarios::Scenario::Load(
        testing::WriteTempFile("appearance_scenario.yaml",
                               "name: appearance\ngarden: test_lawn\nstart: {x: 0.0, y: 0.0, yaw_deg: 0.0}\n"
                               "goals: [{x: 1.0, y: 0.0}]\nstack: {localization: visual}\nvisual_map: " +
                                   map_file + "\n"));
  };
  scenarios::Scenario old = scenario_with(dir + "/old.sqlite");
  try {
    scenarios::ResolveVisualMap(old, {TRIMBOT_SOURCE_DIR}, dir + "/cache");
    ADD_FAILURE() << "a map of an older appearance was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), dir + "/old.sqlite");
    EXPECT_NE(std::string(e.what()).find("appearance version"), std::string::npos) << e.what();
  }
  scenarios::Scenario current = scenario_with(dir + "/current.sqlite");
  EXPECT_NO_THROW(scenarios::ResolveVisualMap(current, {TRIMBOT_SOURCE_DIR}, dir + "/cache"));
}

TEST(VisualMap, RefusesCorruptAndForeignFilesNamingThem) {
  const std::string dir = testing::TempDir("visual_map_bad");
  const std::string good = dir + "/good.sqlite";
  SmallMap().Save(good);
  const auto message = [](const std::function<void()>& load) {
    try {
      load();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message([&] { VisualMap::Load(good, "wageningen"); }).find("made in garden 'test_lawn'"),
            std::string::npos);
  EXPECT_NE(message([&] { VisualMap::Load(good, "", "ffffffffffffffff"); }).find("another camera rig"),
            std::string::npos);
  EXPECT_NE(message([&] { VisualMap::Load(good, "", "", Descriptor::kSift); }).find("descriptor is upright_sift"),
            std::string::npos);
  const std::string garbage = testing::WriteTempFile("garbage.sqlite", "this is not a database at all");
  EXPECT_NE(message([&] { VisualMap::Load(garbage); }).find(garbage), std::string::npos);
  // Truncated: half of a real map file.
  std::ifstream in(good, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string truncated = dir + "/truncated.sqlite";
  std::ofstream(truncated, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_NE(message([&] { VisualMap::Load(truncated); }).find("truncated.sqlite"), std::string::npos);
  EXPECT_NE(message([&] { VisualMap::Load(dir + "/missing.sqlite"); }).find("not found"), std::string::npos);
}

// A map of the first `seconds` of the lawn loop (7 s: ~1 m of driving, 4 keyframes at the 0.3 m
// spacing), built into `dir` (each test builds its own: ctest may run them in any order, in
// parallel). The localization tests use the surveyed builder: they measure the localizer against
// a map whose frame is the garden's to within the survey's noise.
scenarios::MapBuildOptions ShortLawnMap(const std::string& dir, KeyframePoses builder = KeyframePoses::kSurveyed,
                                        double seconds = 7.0) {
  scenarios::MapBuildOptions options;
  options.recipe.plan_path = testing::SourcePath("scenarios/drive_plans/lawn_loop.yaml");
  options.out_dir = dir;
  options.paths = {TRIMBOT_SOURCE_DIR};
  options.recipe.seconds = seconds;
  options.recipe.builder = builder;
  return options;
}

// The mean keyframe error (after a rigid alignment) a log-built map of a straight drive may have
// from its scale alone: the scale is the stereo pairs' calibrated baselines', each known to
// sqrt(2) x the calibration's camera translation error (the default's 1 sigma) over the baseline;
// a scale error e over a straight drive of length L leaves e L / 4 on average. Three sigma of it.
double ScaleErrorBound(const std::string& truth_tum) {
  const std::vector<Eigen::Vector2d> positions = scenarios::ReadTumPositions(truth_tum);
  if (positions.size() < 2) return 0.0;
  const robot::CameraRig rig = robot::LoadCameraRig(robot::RobotFiles::InFolder(testing::SourcePath("robot")));
  const double baseline = rig.StereoPairs().front().baseline;
  const double scale_sigma = std::sqrt(2.0) * scenarios::CalibrationError{}.translation_m / baseline;
  return 3.0 * scale_sigma * (positions.back() - positions.front()).norm() / 4.0;
}

// From the robot's own log (odometry, stereo, the tie to the surveyed garden): the keyframes'
// shape within what the calibration leaves of the scale (1.7 cm on this 2.4 m drive; 1.0 cm
// measured), better than the odometry it started from, and the map's frame within 15 cm of the
// garden's (the tape survey's errors of the few objects 12 s of driving sees). The evaluation's
// files are written.
TEST(MapBuild, ALogBuiltMapOfAShortDriveIsWithinItsStatedErrors) {
  const scenarios::MapBuildOptions options =
      ShortLawnMap(testing::TempDir("map_build_log"), KeyframePoses::kOdometry, 12.0);
  ASSERT_EQ(scenarios::RunMapBuild(options), 0);
  std::ifstream in(options.out_dir + "/map_stats.json");
  const nlohmann::json stats = nlohmann::json::parse(in);
  EXPECT_EQ(stats["builder"], "log");
  EXPECT_GE(stats["keyframes"].get<int>(), 6);
  EXPECT_GT(stats["log"]["stereo_matches"].get<int>(), 1000);
  EXPECT_GT(stats["log"]["tie_points"].get<int>(), 500);
  const auto& built = stats["evaluation"]["keyframes"];
  const auto& odometry = stats["evaluation"]["odometry"];
  std::printf(
      "log map of 12 s: ATE aligned %.4f m (odometry %.4f m), unaligned %.4f m, RPE %.4f m; points median %.3f m\n",
      built["ate_se3_aligned_m"]["mean"].get<double>(), odometry["ate_se3_aligned_m"]["mean"].get<double>(),
      built["ate_unaligned_m"]["mean"].get<double>(), built["rpe_per_keyframe_m"]["mean"].get<double>(),
      stats["evaluation"]["points_to_true_surfaces_m"]["median"].get<double>());
  EXPECT_LT(built["ate_se3_aligned_m"]["mean"].get<double>(),
            ScaleErrorBound(options.out_dir + "/keyframes_truth.tum"));
  EXPECT_LT(built["ate_se3_aligned_m"]["mean"].get<double>(), odometry["ate_se3_aligned_m"]["mean"].get<double>());
  EXPECT_LT(built["ate_unaligned_m"]["mean"].get<double>(), 0.15);
  EXPECT_LT(stats["evaluation"]["points_to_true_surfaces_m"]["median"].get<double>(), 0.05);
  for (const char* file : {"keyframes.tum", "keyframes_odometry.tum", "keyframes_truth.tum", "loops.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(options.out_dir + "/" + file)) << file;
  }
}

// From a folder `trimbot drive` recorded (every ring frame saved): the same map as from driving
// the plan, within the same stated errors as the log-built map above; a saved frame that cannot be
// read is a gap the build reports, not a failure; a malformed sensor log is refused naming the
// file and the line.
TEST(MapBuild, AMapFromARecordedDriveIsWithinItsStatedErrorsAndReportsItsGaps) {
  const std::string recording = testing::TempDir("recorded_lawn_drive");
  std::string plan = testing::ReadText(testing::SourcePath("scenarios/drive_plans/lawn_loop.yaml"));
  plan = std::regex_replace(plan, std::regex("save_every_frames: 10"), "save_every_frames: 1");
  scenarios::DriveOptions drive;
  drive.plan_path = testing::WriteTempFile("lawn_loop_every_frame.yaml", plan);
  drive.output_dir = recording;
  drive.seconds = 10.0;
  drive.quiet = true;
  drive.paths = {TRIMBOT_SOURCE_DIR};
  ASSERT_EQ(scenarios::RunDrive(drive), 0);
  // A second without camera 3 (frames 15-19, 0.3-0.55 m into the drive): one of them is due for a
  // keyframe at the 0.3 m spacing, and each one after it until a frame can be read.
  for (int frame = 15; frame <= 19; ++frame) {
    ASSERT_TRUE(std::filesystem::remove(recording + "/frames/0000" + std::to_string(frame) + "/cam3.png"));
  }

  scenarios::MapBuildOptions options;
  options.recipe.plan_path = recording;
  options.recipe.builder = KeyframePoses::kOdometry;
  options.out_dir = testing::TempDir("map_from_recording");
  options.paths = {TRIMBOT_SOURCE_DIR};
  ASSERT_EQ(scenarios::RunMapBuild(options), 0);
  std::ifstream in(options.out_dir + "/map_stats.json");
  const nlohmann::json stats = nlohmann::json::parse(in);
  EXPECT_GE(stats["keyframes"].get<int>(), 5);
  const auto& built = stats["evaluation"]["keyframes"];
  std::printf("log map of a 10 s recording: ATE aligned %.4f m (odometry %.4f m), unaligned %.4f m\n",
              built["ate_se3_aligned_m"]["mean"].get<double>(),
              stats["evaluation"]["odometry"]["ate_se3_aligned_m"]["mean"].get<double>(),
              built["ate_unaligned_m"]["mean"].get<double>());
  EXPECT_LT(built["ate_se3_aligned_m"]["mean"].get<double>(),
            ScaleErrorBound(options.out_dir + "/keyframes_truth.tum"));
  EXPECT_LT(built["ate_unaligned_m"]["mean"].get<double>(), 0.15);
  EXPECT_LT(stats["evaluation"]["points_to_true_surfaces_m"]["median"].get<double>(), 0.05);
  ASSERT_GE(stats["log"]["frames_unreadable"].size(), 1u);
  for (const auto& gap : stats["log"]["frames_unreadable"]) {
    EXPECT_TRUE(std::regex_search(gap.get<std::string>(), std::regex("00001[5-9]/cam3.png"))) << gap;
  }

  // A malformed sensor log is refused naming the file and the line; the file is restored after.
  const auto expect_refused = [&](const std::string& file, const std::function<void(std::string*)>& spoil,
                                  const std::string& message) {
    const std::string path = recording + "/sensors/" + file, good = testing::ReadText(path);
    std::string broken = good;
    spoil(&broken);
    WriteFileAtomically(path, broken);
    try {
      scenarios::RunMapBuild(options);
      ADD_FAILURE() << file << " was accepted with " << message;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
    WriteFileAtomically(path, good);
  };
  expect_refused(
      "imu.csv", [](std::string* text) { text->insert(text->find('\n', text->find('\n') + 1) + 1, "0.01,1,2\n"); },
      "line 3");
  // An encoder count that is not a whole number.
  expect_refused(
      "wheel_ticks.csv",
      [](std::string* text) {
        const std::size_t line2 = text->find('\n') + 1;
        text->replace(line2, text->find('\n', line2) - line2, "0.0,1.5,2");
      },
      "line 2: tick count 1.5");
}

TEST(MapBuild, AShortDriveGivesAConsistentMap) {
  const scenarios::MapBuildOptions options = ShortLawnMap(testing::TempDir("map_build"));
  ASSERT_EQ(scenarios::RunMapBuild(options), 0);
  std::ifstream in(options.out_dir + "/map_stats.json");
  const nlohmann::json stats = nlohmann::json::parse(in);
  EXPECT_GE(stats["keyframes"].get<int>(), 4);
  EXPECT_GT(stats["points"].get<int>(), 200);
  EXPECT_GT(stats["mean_track_length"].get<double>(), 2.0);
  EXPECT_LT(stats["reprojection_rmse_px"].get<double>(), 3.0);
  const auto& errors = stats["keyframes_against_ground_truth"];
  EXPECT_LT(errors["adjusted_position_error_mean_m"].get<double>(),
            errors["survey_position_error_mean_m"].get<double>())
      << "bundle adjustment brings the keyframes closer to the truth than the survey";
  // The robot's calibration, which the map was built with.
  const robot::CameraRig rig = scenarios::CalibratedRig(
      robot::LoadCameraRig(robot::RobotFiles::InFolder(testing::SourcePath("robot"))), scenarios::CalibrationError{});
  const VisualMap map = VisualMap::Load(options.out_dir + "/map.sqlite", "test_lawn", RigSignature(rig));
  EXPECT_EQ(static_cast<int>(map.points.size()), stats["points"].get<int>());
  EXPECT_GT(map.vocabulary.rows, 10);
  EXPECT_TRUE(std::filesystem::exists(options.out_dir + "/map_top_view.png"));
}

// A frame of another run (other seed: other image noise) along the mapped path: the vocabulary
// retrieves a keyframe within 1 m of the true pose, and the ring's pose comes out within a few
// centimetres - with and without a pose prior. (The robot's calibration, which the map was built
// with, localizes.)
TEST(MapBuild, RenderedFramesAreLocalizedAgainstTheMap) {
  const std::string dir = testing::TempDir("map_for_queries");
  ASSERT_EQ(scenarios::RunMapBuild(ShortLawnMap(dir)), 0);
  const robot::CameraRig rig = scenarios::CalibratedRig(
      robot::LoadCameraRig(robot::RobotFiles::InFolder(testing::SourcePath("robot"))), scenarios::CalibrationError{});
  const scenarios::DrivePlan plan =
      scenarios::DrivePlan::Load(testing::SourcePath("scenarios/drive_plans/lawn_loop.yaml"));
  scenarios::Setting setting = plan.setting;
  setting.seed = 77;
  sim::SimulatorConfig config = scenarios::MakeSimulatorConfig({TRIMBOT_SOURCE_DIR}, setting,
                                                               scenarios::LoadGarden(setting, {TRIMBOT_SOURCE_DIR}),
                                                               testing::TempDir("map_query"));
  config.cameras_on_schedule = false;
  sim::Simulator simulator(config);
  scenarios::DrivePlanPlayer player(plan, 4.1);
  scenarios::LoopOptions loop;
  loop.time_limit = 4.1;
  scenarios::RunClosedLoop(simulator, player, {}, loop);
  const sim::RingCapture capture = simulator.CaptureRing(false);
  const Eigen::Isometry3d truth = simulator.ground_truth().T_map_base;

  for (const auto retrieval : {Retrieval::kVocabulary, Retrieval::kCombined, Retrieval::kPosePrior}) {
    LocalizerOptions options;
    options.retrieval = retrieval;
    if (retrieval == Retrieval::kPosePrior) options.cameras = {0, 2, 4, 6, 8};  // the left cameras alone
    VisualLocalizer localizer(VisualMap::Load(dir + "/map.sqlite", "test_lawn", RigSignature(rig)), rig, options);
    const std::optional<Eigen::Vector2d> prior =
        retrieval == Retrieval::kVocabulary
            ? std::nullopt
            : std::optional<Eigen::Vector2d>(truth.translation().head<2>() + Eigen::Vector2d(0.4, -0.3));
    const LocalizationResult result = localizer.Localize(capture.frame, prior);
    ASSERT_FALSE(result.retrieved.empty());
    const auto& best = localizer.map().keyframes[static_cast<std::size_t>(result.retrieved.front())];
    EXPECT_LT((best.T_map_base.translation() - truth.translation()).head<2>().norm(), 1.0);
    ASSERT_TRUE(result.success) << result.failure;
    const double position_error = (result.T_map_base.translation() - truth.translation()).head<2>().norm();
    const double yaw_error =
        Eigen::AngleAxisd(result.T_map_base.linear().transpose() * truth.linear()).angle() * 180 / M_PI;
    std::printf(
        "localized with %d features, %d matches, %d inliers: %.1f cm, %.2f deg (%.0f ms features, %.0f ms "
        "retrieval, %.0f ms matching, %.0f ms pose)\n",
        result.features, result.matches, result.inliers, 100 * position_error, yaw_error,
        1000 * result.timings.features, 1000 * result.timings.retrieval, 1000 * result.timings.matching,
        1000 * result.timings.pose);
    EXPECT_LT(position_error, 0.05);
    EXPECT_LT(yaw_error, 1.0);
    EXPECT_GT(result.planar_covariance(0, 0), 0.0);
  }
  // The stack on this map asks the ring for what its localizer uses: the left camera of each pair
  // at stack.yaml's image_scale, when a localization is due, and nothing while it is busy.
  robot::RobotFiles files = robot::RobotFiles::InFolder(testing::SourcePath("robot"));
  files.camchain = dir + "/robot_camchain.yaml";  // the robot's calibration, the map's
  WriteFileAtomically(files.camchain, robot::CameraRig::FromCameras(rig.cameras(), files.camchain).ToKalibrYaml());
  const stack::StackParameters parameters = stack::StackParameters::Load(files.stack_parameters);
  ASSERT_EQ(parameters.localization, stack::LocalizationSource::kVisual);
  stack::RobotStack robot(files, parameters, 1);
  robot.SetInitialPose(0.0, {truth.translation().x(), truth.translation().y(), 0.0});
  robot.SetVisualMap(dir + "/map.sqlite");
  const messages::RingRequest request = robot.RingRequestAt(0.2);
  std::vector<int> left;
  for (const auto& pair : rig.StereoPairs()) left.push_back(pair.left);
  std::sort(left.begin(), left.end());
  EXPECT_EQ(request.cameras, left);
  EXPECT_EQ(request.resolution_scale, parameters.visual.image_scale);
  sim::RingCapture asked = simulator.CaptureRing(request, false);
  asked.frame.stamp = 0.2;
  for (auto& image : asked.frame.images) image.stamp = 0.2;
  ASSERT_EQ(asked.frame.images.size(), left.size());
  robot.Add(asked.frame);
  EXPECT_EQ(robot.telemetry().visual.attempts, 1);
  EXPECT_TRUE(robot.RingRequestAt(0.4).empty()) << "busy or above rate_hz: no frame wanted";
  EXPECT_FALSE(robot.RingRequestAt(0.2 + 1.0 / parameters.visual.rate_hz + parameters.visual.latency_max).empty());

  // A frame without images: no fix, a reason.
  messages::RingFrame empty;
  VisualLocalizer localizer(VisualMap::Load(dir + "/map.sqlite"), rig, {});
  const LocalizationResult none = localizer.Localize(empty, std::nullopt);
  EXPECT_FALSE(none.success);
  EXPECT_FALSE(none.failure.empty());
}

// The offline evaluations on a query drive of another seed, 20 cm to the side of the mapped one:
// the bench localizes its frames (fixes, errors against ground truth, a time per stage for every
// frame, the histogram), the retrieval evaluation fills Table 4's rows for the three methods.
TEST(LocalizationEval, BenchAndRetrievalOnAQueryDriveBesideTheMappedOne) {
  const std::string dir = testing::TempDir("map_for_eval");
  ASSERT_EQ(scenarios::RunMapBuild(ShortLawnMap(dir)), 0);
  scenarios::LocalizationEvalOptions options;
  options.map_path = dir + "/map.sqlite";
  options.drive.plan_path = testing::SourcePath("scenarios/drive_plans/lawn_loop.yaml");
  options.drive.seconds = 6.0;
  options.drive.interval = 1.0;
  options.drive.lateral_offset = 0.2;
  options.paths = {TRIMBOT_SOURCE_DIR};
  options.out_dir = dir + "/bench";
  ASSERT_EQ(scenarios::RunLocalizationBench(options), 0);
  std::ifstream bench_file(options.out_dir + "/localization_bench.json");
  const nlohmann::json bench = nlohmann::json::parse(bench_file);
  const int frames = bench["frames"].get<int>();
  EXPECT_GE(frames, 5);
  EXPECT_GE(bench["fix_rate"].get<double>(), 0.8);
  EXPECT_LT(bench["position_error_m"]["median"].get<double>(), 0.05);
  EXPECT_EQ(static_cast<int>(bench["time"]["frames_ms"].size()), frames);
  EXPECT_GT(bench["time"]["total"]["median_ms"].get<double>(), 0.0);
  EXPECT_TRUE(std::filesystem::exists(options.out_dir + "/localization_time.png"));
  // Beside the mapped drive the fixes are what they state (a NEES of 3 on average when they are).
  EXPECT_GT(bench["nees"]["within_95_rate"].get<double>(), 0.8);
  std::ifstream frames_file(options.out_dir + "/localization_frames.csv");
  std::string line;
  int rows = -1;  // the header
  while (std::getline(frames_file, line)) ++rows;
  EXPECT_EQ(rows, frames);

  options.out_dir = dir + "/retrieval";
  ASSERT_EQ(scenarios::RunRetrievalEval(options), 0);
  std::ifstream retrieval_file(options.out_dir + "/retrieval_eval.json");
  const nlohmann::json retrieval = nlohmann::json::parse(retrieval_file);
  const VisualMap map = VisualMap::Load(options.map_path);  // a short map: every keyframe is retrieved
  for (const char* method : {"vocabulary", "pose_prior", "combined"}) {
    const auto& row = retrieval["methods"][method];
    EXPECT_EQ(row["retrieved_keyframes"].get<int>(), frames * std::min<int>(5, map.keyframes.size())) << method;
    const double rig50 = row["rig_percent"][">=50"].get<double>();
    EXPECT_GE(rig50, row["rig_percent"][">=100"].get<double>()) << method;
    EXPECT_GE(row["single_image_percent"][">=50"].get<double>(), row["single_image_percent"][">=200"].get<double>());
  }
  // The nearest keyframes share the most: the rigs' best retrieval has >= 50 verified matches.
  EXPECT_GT(retrieval["methods"]["pose_prior"]["rig_percent"][">=50"].get<double>(), 50.0);
}

}  // namespace
}  // namespace trimbot::visual_localization
