// The trimbot CLI's drive: a short run writes its outputs and a summary that says what happened;
// a broken plan is an input error naming the file. Trim precompute stores what it solved.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "runners/drive.h"
#include "runners/trim_precompute.h"
#include "test_support.h"
#include "trimbot/common/input_error.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/trimming/plan_database.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;

TEST(DriveCommand, ShortDriveWritesFramesLogsAndSummary) {
  DriveOptions options;
  options.plan_path = testing::SourcePath("scenarios/drive_plans/lawn_loop.yaml");
  options.output_dir = testing::TempDir("cli_drive");
  fs::remove_all(options.output_dir);
  options.seconds = 3.0;  // 2 s standing, then 1 s driving at up to 25 cm/s
  options.resolution_scale = 0.5;
  options.quiet = true;
  options.paths = {TRIMBOT_SOURCE_DIR};
  ASSERT_EQ(RunDrive(options), 0);

  const std::string out = options.output_dir;
  std::ifstream summary_file(out + "/summary.json");
  const auto summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["status"], "completed");
  EXPECT_EQ(summary["seed"], 1);
  EXPECT_NEAR(summary["simulated_seconds"].get<double>(), 3.0, 0.01);
  EXPECT_EQ(summary["ring_frames"], 15);
  EXPECT_EQ(summary["obstacle_contact_steps"], 0);
  // The robot moved forward about 0.19 m (1 s: 0.5 s ramp at 0.5 m/s^2, then 0.25 m/s).
  EXPECT_NEAR(summary["path_end"][0].get<double>(), 0.19, 0.02);
  EXPECT_LT(summary["wheel_odometry_end_error_m"].get<double>(), 0.02);
  for (int i = 0; i < 10; ++i) {
    const std::string cam = out + "/frames/000000/cam" + std::to_string(i);
    EXPECT_TRUE(fs::exists(cam + ".png")) << cam;
    EXPECT_TRUE(fs::exists(cam + "_depth.png")) << cam;
    EXPECT_TRUE(fs::exists(cam + "_class.png")) << cam;
  }
  EXPECT_TRUE(fs::exists(out + "/frames/000010/cam9.png"));
  EXPECT_FALSE(fs::exists(out + "/frames/000001"));  // every 10th frame only
  // 200 Hz IMU over 3 s (+ header).
  std::ifstream imu(out + "/sensors/imu.csv");
  const auto lines = std::count(std::istreambuf_iterator<char>(imu), std::istreambuf_iterator<char>(), '\n');
  EXPECT_EQ(lines, 601);
  EXPECT_TRUE(fs::exists(out + "/ground_truth/base.tum"));
  EXPECT_TRUE(fs::exists(out + "/world/world.xml"));
}

// Options for a drive of a plan written to a temporary file.
DriveOptions PlanFile(const std::string& name, const std::string& garden, const std::string& duration) {
  DriveOptions options;
  options.plan_path =
      testing::WriteTempFile(name, "garden: " + garden + "\nseed: 1\nstart: {x: 0, y: 0, yaw_deg: 0}\n" +
                                       "segments:\n  - {duration: " + duration + ", linear: 0, angular: 0}\n");
  options.output_dir = testing::TempDir(name);
  options.paths = {TRIMBOT_SOURCE_DIR};
  return options;
}

TEST(DriveCommand, BrokenPlanIsAnInputErrorNamingTheFile) {
  const DriveOptions options = PlanFile("broken_plan.yaml", "test_lawn", "fast");
  try {
    RunDrive(options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), options.plan_path);
    EXPECT_NE(std::string(e.what()).find("line 5: key 'segments[0].duration': expected a number"), std::string::npos)
        << e.what();
  }
}

TEST(DriveCommand, UnknownGardenIsAnInputError) {
  const DriveOptions options = PlanFile("unknown_garden.yaml", "versailles", "1");
  try {
    RunDrive(options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown garden 'versailles'"), std::string::npos) << e.what();
  }
}

TEST(TrimPrecompute, StoresTheSolvedPathsForThisArmAndRefusesAnUnknownShape) {
  TrimPrecomputeOptions options;
  options.out = testing::TempDir("trim_precompute") + "/paths.sqlite";
  options.shapes = {"ball", "box"};
  options.sizes = {0.3};  // small: few blade poses at the stack's spacing (the test's time)
  options.distances = {0.8};
  ASSERT_EQ(RunTrimPrecompute(options, {TRIMBOT_SOURCE_DIR}), 0);
  const robot::RobotDescription robot = robot::RobotDescription::Load(testing::SourcePath("robot/urdf/trimbot.urdf"));
  const arm::ArmKinematics kinematics(robot);
  const Eigen::Isometry3d T_cutter_blade = robot.BladeInCutter();
  const trimming::CuttingPathDatabase database =
      trimming::CuttingPathDatabase::Load(options.out, trimming::ArmSignature(kinematics, T_cutter_blade));
  ASSERT_EQ(database.size(), 2);
  for (int i = 0; i < 2; ++i) {
    const trimming::StoredCuttingPath& path = database.path(i);
    EXPECT_NEAR(path.target.centre.x(), 0.8, 1e-12);
    EXPECT_NEAR(path.target.half.x(), 0.15, 1e-12);
    ASSERT_FALSE(path.blades.empty());
    // Each stored solution puts the blade on its stored pose.
    for (std::size_t k = 0; k < path.blades.size(); ++k) {
      const Eigen::Isometry3d blade = kinematics.EndEffectorPose(path.configurations[k]) * T_cutter_blade;
      EXPECT_LT((blade.translation() - path.blades[k].translation()).norm(), 1e-3);
    }
  }
  EXPECT_EQ(database.path(1).target.horizontal_exponent, 6.0) << "the box";
  options.shapes = {"cone"};
  try {
    RunTrimPrecompute(options, {TRIMBOT_SOURCE_DIR});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown shape 'cone'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace trimbot::scenarios
