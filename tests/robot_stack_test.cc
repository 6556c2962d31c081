// The robot software alone: RobotStack built from the robot/ files, run on synthetic sensor
// messages from a kinematic unicycle (no simulator, no MuJoCo), with its pose estimate checked
// against the unicycle's true pose. Also: bad stack parameter files name the file and the key.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include "test_support.h"
#include "trimbot/common/input_error.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/stack/robot_stack.h"

namespace trimbot::stack {
namespace {

using testing::SourcePath;

robot::RobotFiles Files() { return robot::RobotFiles::InFolder(SourcePath("robot")); }

// A perfect differential-drive base that turns commands into the messages a driver would send:
// encoder counts at 50 Hz and a gyro + accelerometer at 200 Hz.
class UnicyclePlant {
 public:
  explicit UnicyclePlant(Pose2 start) : pose_(start), geometry_(robot::RobotDescription::Load(Files().urdf).drive()) {}

  // Advances by dt = 5 ms at the commanded speeds; feeds the stack what is due.
  void Step(RobotStack& stack, double linear, double angular) {
    constexpr double dt = 0.005;
    pose_.x += linear * std::cos(pose_.yaw) * dt;
    pose_.y += linear * std::sin(pose_.yaw) * dt;
    pose_.yaw += angular * dt;
    const robot::WheelSpeeds w = geometry_.FromTwist(linear, angular);
    left_ += w.left * dt;
    right_ += w.right * dt;
    ++step_;
    t_ = step_ * dt;
    messages::ImuSample imu;
    imu.stamp = t_;
    imu.linear_acceleration = Eigen::Vector3d(0, 0, 9.81);
    imu.angular_velocity = Eigen::Vector3d(0, 0, angular);
    stack.Add(imu);
    if (step_ % 4 == 0) {
      constexpr double kTicksPerRadian = 2048.0 / (2.0 * M_PI);
      stack.Add(
          messages::WheelTicks{t_, std::llround(left_ * kTicksPerRadian), std::llround(right_ * kTicksPerRadian)});
    }
  }
  const Pose2& pose() const { return pose_; }
  double time() const { return t_; }

 private:
  Pose2 pose_;
  robot::DiffDriveGeometry geometry_;
  double left_ = 0.0, right_ = 0.0, t_ = 0.0;
  long step_ = 0;
};

TEST(RobotStack, BuildsFromTheRobotFilesAndEstimatesAStraightDrive) {
  StackParameters parameters = StackParameters::Load(Files().stack_parameters);
  parameters.localization = LocalizationSource::kNone;
  RobotStack stack(Files(), parameters, 1);
  stack.SetInitialPose(0.0, {1.0, 2.0, 0.3});
  UnicyclePlant plant({1.0, 2.0, 0.3});
  while (plant.time() < 10.0) {
    plant.Step(stack, 0.25, 0.0);
    stack.Update(plant.time());
  }
  const Telemetry& t = stack.telemetry();
  // 2.5 m along a heading of 0.3 rad, dead reckoning on perfect sensors.
  EXPECT_NEAR(t.estimate.pose.x, plant.pose().x, 0.01);
  EXPECT_NEAR(t.estimate.pose.y, plant.pose().y, 0.01);
  EXPECT_NEAR(t.estimate.pose.yaw, 0.3, 0.005);
  EXPECT_NEAR(t.odometry.x, plant.pose().x, 0.01);
  EXPECT_NEAR(t.estimate.linear_velocity, 0.25, 0.01);
  EXPECT_NEAR(plant.pose().x, 1.0 + 2.5 * std::cos(0.3), 0.01) << "the plant itself";
  EXPECT_EQ(t.localization.fixes_accepted, 0);
}

// Writes a 12 x 8 m map_server map, free but for a 1 m block at (4, 0).
std::string WriteMap() {
  const std::string dir = testing::TempDir("robot_stack_map");
  const double resolution = 0.05;
  cv::Mat image(160, 240, CV_8U, cv::Scalar(254));  // free
  // Map origin (-2, -4); the block spans x 3.5..4.5, y -0.5..0.5.
  const int column = static_cast<int>((3.5 + 2.0) / resolution),
            row_top = static_cast<int>(160 - (0.5 + 4.0) / resolution);
  image(cv::Rect(column, row_top, 20, 20)).setTo(0);
  cv::imwrite(dir + "/map.png", image);
  std::ofstream(dir + "/map.yaml") << "image: map.png\nresolution: 0.05\norigin: [-2.0, -4.0, 0.0]\nnegate: 0\n"
                                      "occupied_thresh: 0.65\nfree_thresh: 0.196\n";
  return dir + "/map.yaml";
}

TEST(RobotStack, DrivesAKinematicBaseAroundAnObstacleToItsGoal) {
  StackParameters parameters = StackParameters::Load(Files().stack_parameters);
  parameters.localization = LocalizationSource::kNone;  // dead reckoning on perfect sensors
  RobotStack stack(Files(), parameters, 3);
  stack.SetInitialPose(0.0, {0.0, 0.0, 0.0});
  stack.SetMap(WriteMap());
  stack.SetGoals({Eigen::Vector2d(8.0, 0.0)});
  UnicyclePlant plant({0.0, 0.0, 0.0});
  messages::BaseVelocityCommand command;
  double closest_to_block = 1e9;
  while (plant.time() < 120.0 && stack.telemetry().mission != MissionState::kDone &&
         stack.telemetry().mission != MissionState::kFailed) {
    plant.Step(stack, command.linear, command.angular);
    const messages::RobotCommands commands = stack.Update(plant.time());
    if (commands.base) command = *commands.base;
    closest_to_block = std::min(closest_to_block, std::hypot(plant.pose().x - 4.0, plant.pose().y));
  }
  EXPECT_EQ(stack.telemetry().mission, MissionState::kDone);
  EXPECT_LT(std::hypot(plant.pose().x - 8.0, plant.pose().y), 0.15);
  EXPECT_GT(closest_to_block, 0.5 + 0.3) << "the path keeps the base clear of the block";
}

// A bush whose servo gives up (here: no ring images, so it never sees the bush and times out) ends
// the mission, or with navigation.stop_on_failure false goes as a point goal given up does: the
// robot drives on to the next goal (a batch of trims reports the bush and trims the rest).
TEST(RobotStack, ABushNotReachedEndsTheMissionOnlyWhenGoalsGivenUpDo) {
  for (const bool stop_on_failure : {true, false}) {
    StackParameters parameters = StackParameters::Load(Files().stack_parameters);
    parameters.localization = LocalizationSource::kNone;
    parameters.navigation.stop_on_failure = stop_on_failure;
    parameters.bush_approach.servo.timeout = 5.0;
    RobotStack stack(Files(), parameters, 5);
    stack.SetInitialPose(0.0, {0.0, 0.0, 0.0});
    stack.SetMap(WriteMap());
    perception::BushShape bush;
    bush.size = {0.6, 0.6, 0.5};
    stack.SetGoals({Goal::ApproachBush({2.0, -2.5}, bush), Goal(6.0, 2.0)});
    UnicyclePlant plant({0.0, 0.0, 0.0});
    messages::BaseVelocityCommand command;
    int bush_given_up = 0;
    while (plant.time() < 120.0 && stack.telemetry().mission != MissionState::kDone &&
           stack.telemetry().mission != MissionState::kFailed) {
      plant.Step(stack, command.linear, command.angular);
      const messages::RobotCommands commands = stack.Update(plant.time());
      if (commands.base) command = *commands.base;
      for (const NavigationEvent& e : stack.telemetry().events) {
        bush_given_up += e.type == NavigationEvent::Type::kGoalFailed && e.goal == 0 ? 1 : 0;
      }
    }
    EXPECT_EQ(bush_given_up, 1) << "stop_on_failure " << stop_on_failure;
    if (stop_on_failure) {
      EXPECT_EQ(stack.telemetry().mission, MissionState::kFailed);
    } else {
      EXPECT_EQ(stack.telemetry().mission, MissionState::kDone);
      EXPECT_LT(std::hypot(plant.pose().x - 6.0, plant.pose().y - 2.0), 0.15);
    }
  }
}

TEST(RobotStack, PoseFixesAreUsedOnlyWhenASourceIsConfigured) {
  for (const auto source : {LocalizationSource::kNone, LocalizationSource::kSimulatedPoseFixes}) {
    StackParameters parameters = StackParameters::Load(Files().stack_parameters);
    parameters.localization = source;
    RobotStack stack(Files(), parameters, 1);
    stack.SetInitialPose(0.0, {0.0, 0.0, 0.0});
    UnicyclePlant plant({0.0, 0.0, 0.0});
    for (int k = 1; k <= 400; ++k) {
      plant.Step(stack, 0.0, 0.0);
      if (k % 40 == 0) {
        messages::PoseFix fix;
        fix.stamp = plant.time();
        fix.x = 0.15;  // the fixes say the robot stands 15 cm further east
        fix.covariance = Eigen::Vector3d(0.03 * 0.03, 0.03 * 0.03, 0.01 * 0.01).asDiagonal();
        stack.Add(fix);
      }
      stack.Update(plant.time());
    }
    const Telemetry& t = stack.telemetry();
    if (source == LocalizationSource::kNone) {
      EXPECT_EQ(t.pose_fixes_ignored, 10);
      EXPECT_NEAR(t.estimate.pose.x, 0.0, 1e-3);
    } else {
      EXPECT_EQ(t.localization.fixes_accepted, 10);
      EXPECT_NEAR(t.estimate.pose.x, 0.15, 0.02);
    }
  }
}

// What the stack asks of the ring: nothing without a component that uses images; with local
// fusion, every camera at the calibrated resolution (stereo rectifies with it) when a cloud is due.
TEST(RobotStack, AsksTheRingOnlyForWhatItsComponentsUse) {
  StackParameters parameters = StackParameters::Load(Files().stack_parameters);
  parameters.localization = LocalizationSource::kNone;
  parameters.local_fusion.enabled = false;
  {
    RobotStack stack(Files(), parameters, 1);
    EXPECT_TRUE(stack.RingRequestAt(0.0).empty());
  }
  parameters.local_fusion.enabled = true;
  RobotStack stack(Files(), parameters, 1);
  const messages::RingRequest request = stack.RingRequestAt(0.0);
  ASSERT_EQ(request.cameras.size(), 10u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(request.cameras[static_cast<std::size_t>(i)], i);
  EXPECT_EQ(request.resolution_scale, 1.0);
}

// A copy of robot/config/stack.yaml with one line changed (or removed when `replacement` is empty).
std::string Variant(const std::string& name, const std::string& pattern, const std::string& replacement) {
  std::ifstream in(Files().stack_parameters);
  std::stringstream text;
  text << in.rdbuf();
  const std::string changed =
      std::regex_replace(text.str(), std::regex(pattern), replacement, std::regex_constants::format_first_only);
  EXPECT_NE(changed, text.str()) << pattern;
  return testing::WriteTempFile(name, changed);
}

TEST(StackParameters, BadFilesNameTheFileAndTheKey) {
  struct Case {
    const char* name;
    const char* pattern;
    const char* replacement;
    const char* message;
  };
  const Case cases[] = {
      {"missing.yaml", "  gyro_sigma: [^\n]*\n", "", "key 'ekf.gyro_sigma': missing"},
      {"unknown.yaml", "  gyro_sigma:", "  gyro_sigmaa: 0.005\n  gyro_sigma:", "key 'ekf.gyro_sigmaa'"},
      {"nan.yaml", "gyro_sigma: 0.005", "gyro_sigma: .nan", "key 'ekf.gyro_sigma': must be a finite number"},
      {"inf.yaml", "cruise_speed: 0.25", "cruise_speed: .inf",
       "key 'navigation.follower.cruise_speed': must be a finite"},
      {"range.yaml", "cruise_speed: 0.25", "cruise_speed: 2.0",
       "key 'navigation.follower.cruise_speed': must be in [0.01, 0.6]"},
      {"negative.yaml", "iterations: 3000", "iterations: -5", "key 'navigation.planner.iterations': must be in"},
      {"source.yaml", "localization: visual", "localization: gps", "unknown source 'gps'"},
      {"type.yaml", "enabled: false", "enabled: maybe", "key 'perception.local_fusion.enabled': expected a boolean"},
  };
  for (const Case& c : cases) {
    const std::string path = Variant(c.name, c.pattern, c.replacement);
    try {
      StackParameters::Load(path);
      ADD_FAILURE() << c.name << " was accepted";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      EXPECT_NE(message.find(c.message), std::string::npos) << c.name << ": " << message;
    }
  }
}

TEST(StackParameters, OverridesReplaceOnlyTheKeysGiven) {
  const StackParameters defaults = StackParameters::Load(Files().stack_parameters);
  const std::string path = testing::WriteTempFile(
      "overrides.yaml",
      "stack:\n  localization: simulated_pose_fixes\n  navigation: {follower: {cruise_speed: 0.3}}\n");
  const YamlMap root = YamlMap::LoadFile(path);
  const StackParameters p = defaults.Overridden(root.Map("stack"));
  EXPECT_EQ(p.localization, LocalizationSource::kSimulatedPoseFixes);
  EXPECT_DOUBLE_EQ(p.navigation.follower.cruise_speed, 0.3);
  EXPECT_DOUBLE_EQ(p.navigation.follower.lookahead, defaults.navigation.follower.lookahead);
  EXPECT_DOUBLE_EQ(p.ekf.gyro_sigma, defaults.ekf.gyro_sigma);

  const std::string bad = testing::WriteTempFile("overrides_bad.yaml", "stack:\n  navigation: {folower: {}}\n");
  try {
    defaults.Overridden(YamlMap::LoadFile(bad).Map("stack"));
    ADD_FAILURE() << "unknown override accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("stack.navigation.folower"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace trimbot::stack
