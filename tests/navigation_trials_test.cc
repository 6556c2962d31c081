// Navigation scenarios and batches: the scenario files, their bad-input errors, a closed-loop
// trial with injected faults, shards merged into the whole batch, and trials that time out.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>

#include "evaluation/contact_events.h"
#include "loop/prior_knowledge.h"
#include "loop/scenario.h"
#include "loop/simulated_pose_fixes.h"
#include "runners/batch.h"
#include "runners/suite.h"
#include "runners/trial.h"
#include "test_support.h"
#include "trimbot/common/input_error.h"
#include "trimbot/garden/conditions.h"
#include "trimbot/garden/garden.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/stack/global_planner.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/stack/stack_parameters.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

// The smoke scenario with `replace` -> `with` applied to its text, written to a temp file.
std::string SmokeVariant(const std::string& name, const std::string& replace, const std::string& with) {
  std::string text = testing::ReadText(testing::SourcePath("scenarios/navigation/smoke.yaml"));
  if (!replace.empty()) text = std::regex_replace(text, std::regex(replace), with);
  return testing::WriteTempFile(name, text);
}

// Loading the scenario at `path` is refused with an InputError naming `file` and the `problem`.
void ExpectLoadError(const std::string& path, const std::string& file, const std::string& problem) {
  try {
    Scenario::Load(path);
    ADD_FAILURE() << "accepted: " << path;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
  }
}

// An arm contact counts once while the pair touches (MuJoCo reports a pair once per contact point),
// again when it touches anew, and names the two geoms.
TEST(ContactEvents, APairCountsOnceWhileItTouchesAndIsNamed) {
  ContactEvents events;
  const sim::ArmContact wood{"arm_link_6", "bush_2_wood", 0.001}, ground{"arm_link_3", "ground", 0.002};
  const auto first = events.Update({wood, wood, ground});  // two contact points of the first pair
  ASSERT_EQ(first.size(), 2u);
  EXPECT_EQ(first[0], std::make_pair(std::string("arm_link_3"), std::string("ground")));
  EXPECT_EQ(first[1], std::make_pair(std::string("arm_link_6"), std::string("bush_2_wood")));
  EXPECT_TRUE(events.Update({wood}).empty()) << "still touching";
  EXPECT_TRUE(events.Update({}).empty());
  EXPECT_EQ(events.Update({wood}).size(), 1u) << "touching anew";
}

TEST(Scenario, TheRealRobotsTrialSetsLoad) {
  for (const std::string name : {"rectangle", "hourglass"}) {
    const Scenario s = Scenario::Load(testing::SourcePath("scenarios/navigation/" + name + ".yaml"));
    EXPECT_EQ(s.name, name);
    EXPECT_EQ(s.goals.size(), 4u);
    EXPECT_EQ(s.trials, 6);
    EXPECT_NEAR((s.goals.back().position - Eigen::Vector2d(s.setting.start.x, s.setting.start.y)).norm(), 0.0, 1e-9)
        << "a loop";
    ASSERT_TRUE(s.stack.has_value());
    EXPECT_EQ(StackParametersFor(s, ProjectPaths{TRIMBOT_SOURCE_DIR}).localization,
              stack::LocalizationSource::kSimulatedPoseFixes);
    EXPECT_GT(s.initial_position_sigma, 0.0) << "never the true start";
    EXPECT_FALSE(s.criteria.empty());
  }
}

// Between consecutive hourglass goals the straight line is blocked for the robot (as in the real
// trials, it has to plan around the bushes), and the base fits at every goal.
TEST(Scenario, HourglassHasNoStraightPathBetweenGoals) {
  const Scenario s = Scenario::Load(testing::SourcePath("scenarios/navigation/hourglass.yaml"));
  const garden::OccupancyMap prior = PrepareTrial(s, ProjectPaths{TRIMBOT_SOURCE_DIR}).prior_map;
  const stack::OccupancyGrid map(prior.occupied, prior.resolution, prior.origin);
  const auto [outline_min, outline_max] =
      robot::RobotDescription::Load(robot::RobotFiles::InFolder(testing::SourcePath("robot")).urdf).BaseOutline();
  const stack::GlobalPlanner planner(map, stack::BaseOutline(outline_min, outline_max), stack::PlannerParameters{});
  const double wanted = planner.parameters().min_clearance;
  Eigen::Vector2d from(s.setting.start.x, s.setting.start.y);
  for (const auto& scenario_goal : s.goals) {
    const Eigen::Vector2d goal = scenario_goal.position;
    EXPECT_TRUE(planner.FreeHeading(goal).has_value()) << "goal " << goal.transpose() << " is not reachable";
    const double heading = std::atan2(goal.y() - from.y(), goal.x() - from.x());
    double closest = 1e9;
    for (double f = 0.0; f <= 1.0; f += 0.005) {
      const Eigen::Vector2d q = from + f * (goal - from);
      closest = std::min(closest, planner.Clearance({q.x(), q.y(), heading}));
    }
    EXPECT_LT(closest, wanted) << "straight path from " << from.transpose() << " to " << goal.transpose();
    from = goal;
  }
}

// The prior map is the garden as surveyed: unmapped objects are missing from it, objects that are
// gone are still in it, foliage is as big as it was at the survey.
TEST(PriorKnowledge, TheMapIsTheGardenAsSurveyed) {
  const garden::Garden built = garden::Garden::Load(testing::SourcePath("garden_scenes/gardens/wageningen.yaml"));
  Survey survey;
  survey.point_sigma = 0.0;  // exact, to see growth, unmapped and gone alone
  survey.growth = 1.0;
  survey.unmapped = {17};
  garden::GardenObject gone;
  gone.id = 900;
  gone.size = Eigen::Vector3d(0.5, 0.5, 0.5);
  gone.position = Eigen::Vector2d(0.0, 3.0);
  survey.gone = {gone};
  const garden::Garden surveyed = SurveyedGarden(built, survey, "test.yaml");
  EXPECT_EQ(surveyed.objects.size(), built.objects.size());  // one out, one in
  const auto find = [](const garden::Garden& g, int id) {
    return std::find_if(g.objects.begin(), g.objects.end(), [id](const auto& o) { return o.id == id; });
  };
  EXPECT_EQ(find(surveyed, 17), surveyed.objects.end());
  EXPECT_NE(find(surveyed, 900), surveyed.objects.end());
  const auto built_bush = find(built, 9), surveyed_bush = find(surveyed, 9);  // topiary
  EXPECT_NEAR(surveyed_bush->size.x() - built_bush->size.x(), 2 * garden::kMaxGrowth, 1e-12);
  EXPECT_EQ(surveyed_bush->size.z(), built_bush->size.z());
  const auto fence = find(built, 5);
  EXPECT_EQ(find(surveyed, 5)->size, fence->size) << "a fence does not grow";
  survey.unmapped = {12345};
  EXPECT_THROW(SurveyedGarden(built, survey, "test.yaml"), InputError);
}

// A tape survey's errors: centres off by the point sigma per axis, extents by sqrt(2) of it, the
// yaw of elongated objects by sqrt(2) of it over their length, round ones' not at all; the same
// seed gives the same survey, another seed another.
TEST(PriorKnowledge, ASurveyCarriesTapeErrors) {
  const garden::Garden built = garden::Garden::Load(testing::SourcePath("garden_scenes/gardens/wageningen.yaml"));
  Survey survey;
  survey.seed = 11;
  ASSERT_EQ(survey.point_sigma, kTapeSurveyPointSigma) << "surveys carry errors by default";
  const garden::Garden surveyed = SurveyedGarden(built, survey, "test.yaml");
  ASSERT_EQ(surveyed.objects.size(), built.objects.size());
  double centre_sq = 0.0, extent_sq = 0.0;
  int centres = 0, extents = 0;
  for (std::size_t i = 0; i < built.objects.size(); ++i) {
    const garden::GardenObject &truth = built.objects[i], &seen = surveyed.objects[i];
    ASSERT_EQ(truth.id, seen.id);
    centre_sq += (seen.position - truth.position).squaredNorm();
    centres += 2;
    for (int k = 0; k < 3; ++k) {
      if (seen.size[k] > 0.5 * truth.size[k]) {  // not clamped
        extent_sq += std::pow(seen.size[k] - truth.size[k], 2);
        ++extents;
      }
    }
    const bool round = truth.shape != garden::Shape::kBox && truth.size.x() == truth.size.y();
    if (round) {
      EXPECT_EQ(seen.yaw, truth.yaw) << "object " << truth.id;
    } else {
      EXPECT_NE(seen.yaw, truth.yaw) << "object " << truth.id;
    }
  }
  ASSERT_GT(centres, 40);
  // Sample standard deviations of 40+ draws: within 30 % of the sigma is beyond 3 of their sigmas.
  EXPECT_NEAR(std::sqrt(centre_sq / centres), survey.point_sigma, 0.3 * survey.point_sigma);
  EXPECT_NEAR(std::sqrt(extent_sq / extents), std::sqrt(2.0) * survey.point_sigma, 0.3 * survey.point_sigma);

  const garden::Garden again = SurveyedGarden(built, survey, "test.yaml");
  EXPECT_EQ(again.objects[0].position, surveyed.objects[0].position);
  survey.seed = 12;
  EXPECT_NE(SurveyedGarden(built, survey, "test.yaml").objects[0].position, surveyed.objects[0].position);
}

// A survey drawn per trial (narrow_gap.yaml) is seeded by the trial's seed: the trial with the
// batch's seed gets the batch's survey, another trial another survey, prior map and mission, and the
// world and the truth stay the batch's. A `seed` beside `per_trial` contradicts it and is refused.
TEST(PriorKnowledge, ASurveyDrawnPerTrialTakesTheTrialsSeed) {
  const ProjectPaths paths{TRIMBOT_SOURCE_DIR};
  const Scenario s = Scenario::Load(testing::SourcePath("scenarios/navigation/narrow_gap.yaml"));
  ASSERT_TRUE(s.survey.per_trial);
  const PreparedTrial batch = PrepareTrial(s, paths);
  const PreparedTrial first = WithTrialSurvey(batch, s, s.setting.seed);
  const PreparedTrial second = WithTrialSurvey(batch, s, s.setting.seed + 1);
  ASSERT_EQ(first.surveyed.objects.size(), second.surveyed.objects.size());
  EXPECT_EQ(first.surveyed.objects[0].position, batch.surveyed.objects[0].position);
  EXPECT_EQ(cv::countNonZero(first.prior_map.occupied != batch.prior_map.occupied), 0);
  EXPECT_NE(second.surveyed.objects[0].position, batch.surveyed.objects[0].position);
  EXPECT_GT(cv::countNonZero(second.prior_map.occupied != batch.prior_map.occupied), 0);
  EXPECT_EQ(second.garden.objects[0].position, batch.garden.objects[0].position);
  EXPECT_EQ(second.goal_truths[0].position, batch.goal_truths[0].position);

  const std::string text = testing::ReadText(testing::SourcePath("scenarios/navigation/narrow_gap.yaml"));
  const std::string seeded = testing::WriteTempFile(
      "per_trial_seed.yaml", std::regex_replace(text, std::regex("per_trial: true"), "per_trial: true, seed: 3"));
  ExpectLoadError(seeded, "per_trial_seed.yaml", "seed");
}

// The stack starts from the true start plus the seeded placement error, and reads a calibration
// with the seeded calibration error; the simulator keeps the true one.
TEST(PriorKnowledge, StartAndCalibrationCarryTheirSeededErrors) {
  const ProjectPaths paths{TRIMBOT_SOURCE_DIR};
  Scenario s = Scenario::Load(testing::SourcePath("scenarios/navigation/rectangle.yaml"));
  const Pose2 a = BelievedStart(s, 1), b = BelievedStart(s, 1), c = BelievedStart(s, 2);
  EXPECT_EQ(a.x, b.x);
  EXPECT_NE(a.x, c.x);
  const double error = std::hypot(a.x - s.setting.start.x, a.y - s.setting.start.y);
  EXPECT_GT(error, 0.0);
  EXPECT_LT(error, 5 * s.initial_position_sigma);

  // The robot's calibration is on by default (Kalibr's residuals); zeros give the true camchain.
  EXPECT_TRUE(s.calibration_error.any());
  EXPECT_EQ(s.visual_map_recipe ? s.visual_map_recipe->calibration_error.seed : s.calibration_error.seed,
            s.calibration_error.seed);
  Scenario exact = s;
  exact.calibration_error = CalibrationError{0, 0.0, 0.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(StackCalibration(exact, paths, testing::TempDir("calibration")), paths.robot_files().camchain);
  EXPECT_EQ(CameraImuTimeOffset(exact.calibration_error), 0.0);
  EXPECT_NE(CameraImuTimeOffset(s.calibration_error), 0.0);
  s.calibration_error.focal_relative = 0.01;
  s.calibration_error.rotation_deg = 0.5;
  const std::string perturbed = StackCalibration(s, paths, testing::TempDir("calibration"));
  const robot::RobotDescription description = robot::RobotDescription::Load(paths.robot_files().urdf);
  const Eigen::Isometry3d T_base_cam0 = description.FramePose(robot::RobotFrames::CameraOptical(0));
  const robot::CameraRig truth = robot::CameraRig::LoadKalibr(paths.robot_files().camchain, T_base_cam0);
  const robot::CameraRig read = robot::CameraRig::LoadKalibr(perturbed, T_base_cam0);
  ASSERT_EQ(read.size(), truth.size());
  double worst_focal = 0.0, worst_angle = 0.0;
  for (int i = 0; i < truth.size(); ++i) {
    worst_focal = std::max(worst_focal, std::abs(read.camera(i).intrinsics.fx / truth.camera(i).intrinsics.fx - 1.0));
    const Eigen::AngleAxisd delta(truth.camera(i).T_base_camera.linear().transpose() *
                                  read.camera(i).T_base_camera.linear());
    worst_angle = std::max(worst_angle, delta.angle() * 180.0 / M_PI);
  }
  EXPECT_GT(worst_focal, 0.001);
  EXPECT_LT(worst_focal, 0.05);
  EXPECT_GT(worst_angle, 0.05);
  EXPECT_LT(worst_angle, 3.0);
}

// The stack's parameters for `s` are refused with an InputError naming `file` and the `problem`.
void ExpectStackParametersError(const Scenario& s, const std::string& file, const std::string& problem) {
  try {
    StackParametersFor(s, ProjectPaths{TRIMBOT_SOURCE_DIR});
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
  }
}

// The stack's default localization is visual: a scenario that neither names a map nor chooses
// another source is refused, naming the file.
// D3.4's localization rate of the fixture's fixes over `seconds` of a 5 Hz ring: the share of 10 Hz
// samples, from the first fix on, with a fix stamped within 0.5 s.
double FixtureLocalizationRate(const SimulatedPoseFixParameters& parameters, double seconds) {
  SimulatedPoseFixes fixes(parameters, 7);
  std::vector<messages::PoseFix> out;
  sim::GroundTruth truth;
  for (int step = 0; step * 0.05 < seconds; ++step) {
    truth.stamp = step * 0.05;
    truth.ring_exposed = step % 4 == 0;
    fixes.Step(truth, &out);
  }
  std::vector<double> stamps;
  for (const auto& fix : out) stamps.push_back(fix.stamp);
  std::sort(stamps.begin(), stamps.end());
  int samples = 0, localized = 0;
  for (double t = stamps.front(); t < seconds - 1.0; t += 0.1, ++samples) {
    const auto next = std::lower_bound(stamps.begin(), stamps.end(), t - 0.5);
    localized += next != stamps.end() && *next <= t + 0.5 ? 1 : 0;
  }
  return static_cast<double>(localized) / samples;
}

// The fixture's frames fail in spells, so its localization rate is the robot's (D3.4 Table 2:
// 92.3 %) while 85 % of frames localize; failing frame by frame would give nearly 100 %.
TEST(SimulatedPoseFixes, OutagesComeInSpellsAsTheRobotsLocalizationRateImplies) {
  SimulatedPoseFixParameters parameters;
  const double clustered = FixtureLocalizationRate(parameters, 4000.0);
  EXPECT_NEAR(clustered, 0.923, 0.02);
  parameters.outage_mean_duration = 0.0;
  const double independent = FixtureLocalizationRate(parameters, 4000.0);
  EXPECT_GT(independent, 0.99);
  std::cout << "localization rate: outages in spells " << clustered << ", frame by frame " << independent << "\n";
}

TEST(Scenario, VisualLocalizationWithoutAMapIsAnInputError) {
  const Scenario s = Scenario::Load(SmokeVariant("no_map.yaml", "stack: \\{localization: none\\}[^\\n]*\\n", ""));
  ExpectStackParametersError(s, "no_map.yaml", "names no visual_map");
}

TEST(Scenario, FixtureSettingsWithoutTheFixtureAreAnInputError) {
  const Scenario s = Scenario::Load(SmokeVariant("unused_fixes.yaml", "time_limit: 60.0",
                                                 "time_limit: 60.0\nsimulated_pose_fixes: {availability: 0.5}"));
  ExpectStackParametersError(s, "unused_fixes.yaml", "localization is 'none'");
}

// A bush goal names a bush of the garden as surveyed: an unknown id, or an object that is not a
// bush (the test lawn's hedge), is refused naming the scenario and the goal.
TEST(Scenario, ApproachBushNeedsABushOfTheGarden) {
  for (const auto& [goal, problem] : std::vector<std::pair<std::string, std::string>>{
           {"{approach_bush: 999}", "has no object 999"}, {"{approach_bush: 5}", "is a hedge, not a bush"}}) {
    const Scenario s = Scenario::Load(SmokeVariant("bad_bush.yaml", "\\{x: 4.0, y: 0.0, yaw_deg: 90.0\\}", goal));
    try {
      PrepareTrial(s, ProjectPaths{TRIMBOT_SOURCE_DIR});
      ADD_FAILURE() << goal << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad_bush.yaml"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
    }
  }
  // A real bush gives the stack its surveyed centre and shape: the survey's, off the true centre
  // (1.5, -2.2) by the survey's error, and the truth stays with the evaluation.
  const Scenario ok =
      Scenario::Load(SmokeVariant("good_bush.yaml", "\\{x: 4.0, y: 0.0, yaw_deg: 90.0\\}", "{approach_bush: 3}"));
  const PreparedTrial prepared = PrepareTrial(ok, ProjectPaths{TRIMBOT_SOURCE_DIR});
  const std::vector<stack::Goal>& goals = prepared.mission;
  ASSERT_EQ(goals.size(), 1u);
  ASSERT_TRUE(goals[0].bush.has_value());
  EXPECT_EQ(goals[0].bush->kind, perception::BushShape::Kind::kCylinder);
  EXPECT_EQ(goals[0].position, BushOf(prepared.surveyed, 3, ok, "test").position);
  const double survey_error = (goals[0].position - Eigen::Vector2d(1.5, -2.2)).norm();
  EXPECT_GT(survey_error, 0.0);
  EXPECT_LT(survey_error, 4.0 * std::sqrt(2.0) * ok.survey.point_sigma);
  EXPECT_EQ(prepared.goal_truths[0].position, Eigen::Vector2d(1.5, -2.2));
}

// A trim goal names a topiary (a rose has no target shape), a goal approaches or trims, and stored
// cutting paths are for trim goals: each refused naming the scenario and the problem.
TEST(Scenario, TrimBushNeedsATopiaryAndTheDatabaseATrim) {
  const Scenario rose =
      Scenario::Load(SmokeVariant("trim_rose.yaml", "\\{x: 4.0, y: 0.0, yaw_deg: 90.0\\}", "{trim_bush: 3}"));
  try {
    PrepareTrial(rose, ProjectPaths{TRIMBOT_SOURCE_DIR});
    ADD_FAILURE() << "a rose accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("trim_rose.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("is a rose, not a topiary"), std::string::npos) << e.what();
  }
  for (const auto& [replacement, problem] : std::vector<std::pair<std::string, std::string>>{
           {"{trim_bush: 1, approach_bush: 1}", "approaches, scans or trims a bush, one of them"},
           {"{x: 4.0, y: 0.0}\ncutting_path_database: paths.sqlite", "is for trim goals"}}) {
    try {
      Scenario::Load(SmokeVariant("bad_trim.yaml", "\\{x: 4.0, y: 0.0, yaw_deg: 90.0\\}", replacement));
      ADD_FAILURE() << replacement << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad_trim.yaml"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
    }
  }
  const Scenario ok = Scenario::Load(
      SmokeVariant("trim_ok.yaml", "\\{x: 4.0, y: 0.0, yaw_deg: 90.0\\}", "{trim_bush: 1, side_deg: 90.0}"));
  const PreparedTrial prepared = PrepareTrial(ok, ProjectPaths{TRIMBOT_SOURCE_DIR});
  ASSERT_EQ(prepared.mission.size(), 1u);
  EXPECT_TRUE(prepared.mission[0].trim);
  EXPECT_TRUE(prepared.mission[0].bush.has_value());
  ASSERT_TRUE(prepared.mission[0].side.has_value());
  EXPECT_DOUBLE_EQ(*prepared.mission[0].side, M_PI / 2.0);
}

// A goal that some headings cannot arrive at (the footprint would touch a rose on the last
// segment): RRT* joins a goal only from its nearest node and failed on this one a third of the
// time; the planner now arrives from a side that works.
TEST(Planner, ReachesAGoalOnlySomeHeadingsCanArriveAt) {
  Scenario s = Scenario::Load(testing::SourcePath("scenarios/navigation/rectangle.yaml"));
  const garden::OccupancyMap prior = PrepareTrial(s, ProjectPaths{TRIMBOT_SOURCE_DIR}).prior_map;
  const stack::OccupancyGrid map(prior.occupied, prior.resolution, prior.origin);
  const auto [min, max] =
      robot::RobotDescription::Load(ProjectPaths{TRIMBOT_SOURCE_DIR}.robot_files().urdf).BaseOutline();
  const stack::GlobalPlanner planner(
      map, stack::BaseOutline(min, max),
      stack::StackParameters::Load(testing::SourcePath("robot/config/stack.yaml")).navigation.planner);
  const Pose2 start{0.29, -0.44, 0.0};
  const Eigen::Vector2d goal(0.49, 0.94);
  for (int run = 0; run < 12; ++run) {
    stack::SeedPlanner(static_cast<std::uint64_t>(run) + 1);  // the same 12 runs every time
    const stack::PlanResult plan = planner.Plan(start, goal, 0.3);
    ASSERT_TRUE(plan.found) << "run " << run << ": " << plan.message;
    EXPECT_LE((plan.path.back() - goal).norm(), 0.3 + 1e-9);
  }
}

TEST(Scenario, BadFilesNameTheFileLineAndKey) {
  const struct {
    std::string replace, with, expected;
  } cases[] = {
      {"goal_tolerance: 0.4", "goal_tolerence: 0.4", "goal_tolerence"},
      {"trials: 1", "trials: many", "trials"},
      {"time_limit: 60.0", "time_limit: 60.0\nfaults:\n  - {type: gremlins, start: 1.0}", "gremlins"},
      {"collisions: \\{max: 0\\}", "colisions: {max: 0}", "colisions"},
      {"success_rate: \\{min: 1.0\\}", "success_rate: {min: 1.0, max: 2.0}", "exactly one"},
      {"goal_tolerance: 0.4", "goal_tolerance: -0.3", "goal_tolerance"},
      {"goal_tolerance: 0.4", "goal_tolerance: 0.4\ngoal_tolerance: 0.5", "appears twice"},
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
  Scenario clean =
      Scenario::Load(SmokeVariant("fixes.yaml", "localization: none", "localization: simulated_pose_fixes"));
  const PreparedTrial world = PrepareTrial(clean, paths);  // the faults change nothing of it
  WritePriorMap(world.prior_map, out + "/map");

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
    return RunTrial({&s, &world, paths, out + "/map/map.yaml", out + "/" + name, 0, 3});
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
  // Each batch records the build that ran it (trimbot ablate reuses only batches of its own build).
  const std::string build = ReadJson(root + "/shard0/batch.json").value("build", "");
  EXPECT_EQ(build.size(), 16u);
  EXPECT_EQ(build, BuildFingerprint());
  const json summary = ReadJson(root + "/merged/summary.json");
  ASSERT_EQ(summary["trials"].size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(summary["trials"][i]["index"], i);
    EXPECT_EQ(summary["trials"][i]["seed"], 40 + i);
    EXPECT_TRUE(summary["trials"][i]["success"].get<bool>());
  }
  EXPECT_EQ(summary["metrics"]["success_rate"], 1.0);
  EXPECT_TRUE(summary["pass"].get<bool>());
  EXPECT_NE(testing::ReadText(root + "/merged/junit.xml").find("tests=\""), std::string::npos);
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
  const std::string original = testing::ReadText(root + "/merged/trials/001/ground_truth.tum");
  EXPECT_FALSE(original.empty());
  EXPECT_EQ(testing::ReadText(root + "/replay/trials/000/ground_truth.tum"), original);
  EXPECT_NE(testing::ReadText(root + "/merged/trials/000/ground_truth.tum"), original) << "another seed, another run";
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
  const std::string junit = testing::ReadText(out + "/junit.xml");
  EXPECT_NE(junit.find("<failure"), std::string::npos);
}

// Places a scenario names that cannot be are refused before any trial runs, naming the scenario
// file, the start or goal, and the object.
TEST(Scenario, StartsAndGoalsThatCannotBeAreRefusedNamingTheObject) {
  const ProjectPaths paths{TRIMBOT_SOURCE_DIR};
  const struct {
    std::string replace, with, expected;
  } cases[] = {
      {"- \\{x: 4.0, y: 0.0, yaw_deg: 90.0\\}", "- {x: 20.0, y: 0.0}",
       "goals[0] at (20, 0) is outside the garden 'test_lawn'"},
      {"- \\{x: 4.0, y: 0.0, yaw_deg: 90.0\\}", "- {x: 8.5, y: 0.0}",
       "goals[0] at (8.5, 0) lies inside object 5 (hedge)"},
      {"start: \\{x: 0.0, y: 0.0, yaw_deg: 0.0\\}", "start: {x: 3.0, y: 1.2, yaw_deg: 0.0}",
       "start: the base's outline at (3, 1.2) overlaps object 1 (topiary)"},
      // Outside the topiary (radius 0.4 m), but facing it the base's front reaches 0.58 m ahead.
      {"- \\{x: 4.0, y: 0.0, yaw_deg: 90.0\\}", "- {x: 2.3, y: 1.2, yaw_deg: 0.0}",
       "goals[0] with its heading: the base's outline at (2.3, 1.2) overlaps object 1 (topiary)"},
  };
  for (const auto& c : cases) {
    const std::string path = SmokeVariant("places.yaml", c.replace, c.with);
    const Scenario s = Scenario::Load(path);
    try {
      PrepareTrial(s, paths);
      ADD_FAILURE() << "accepted: " << c.with;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
    }
  }
}

// A bush goal's heading is the servo's bearing to the bush: a heading given for one is refused.
TEST(Scenario, ABushGoalTakesNoHeading) {
  const std::string path =
      SmokeVariant("bush_heading.yaml", "\\{x: 4.0, y: 0.0, yaw_deg: 90.0\\}", "{approach_bush: 3, yaw_deg: 90}");
  ExpectLoadError(path, "bush_heading.yaml", "a bush goal's heading");
}

// The suite's goal rule never asks the planner: uniform over the cells at least the outline's
// half-width plus the margin from every obstacle (the start: its reach plus the margin), the same
// for the same seed; a garden with no such cell is refused naming it.
TEST(Suite, GoalsAreDrawnWhereTheRuleSaysAndTheSameForTheSameSeed) {
  garden::GeneratorParameters parameters;
  parameters.seed = 7;
  parameters.size = {8.0, 6.0};
  parameters.corridors = 1;
  const garden::Garden garden = garden::GenerateGarden(parameters);
  const double goal_distance = 0.305, start_distance = 0.68;
  const SuiteLayout a = PlaceSuiteLayout(garden, 1.0, goal_distance, start_distance, 20, 11, "garden");
  const SuiteLayout b = PlaceSuiteLayout(garden, 1.0, goal_distance, start_distance, 20, 11, "garden");
  const SuiteLayout c = PlaceSuiteLayout(garden, 1.0, goal_distance, start_distance, 20, 12, "garden");
  ASSERT_EQ(a.goals.size(), 20u);
  EXPECT_EQ(a.goals, b.goals);
  EXPECT_NE(a.goals, c.goals);
  // Around each place, no object's footprint within its distance (less a cell's diagonal: the map's
  // cells are whole squares).
  const auto clear_within = [&](const Eigen::Vector2d& p, double r) {
    for (int k = 0; k < 64; ++k) {
      const double angle = 2.0 * M_PI * k / 64;
      for (double d = 0.0; d <= r - 0.071; d += 0.02) {
        if (garden::ObjectAt(garden, p + d * Eigen::Vector2d(std::cos(angle), std::sin(angle)), 1.0) != nullptr) {
          return false;
        }
      }
    }
    return true;
  };
  for (const auto& goal : a.goals) EXPECT_TRUE(clear_within(goal, goal_distance)) << goal.transpose();
  EXPECT_TRUE(clear_within({a.start.x, a.start.y}, start_distance));
  // Inside the fence.
  for (const auto& goal : a.goals) EXPECT_LT(goal.cwiseAbs().maxCoeff(), 4.0) << goal.transpose();

  garden::Garden full = garden;
  garden::GardenObject block;
  block.id = 900;
  block.object_class = garden::ObjectClass::kObstacle;
  block.shape = garden::Shape::kBox;
  block.size = {30.0, 30.0, 1.0};
  full.AddObjects({block});
  EXPECT_THROW(PlaceSuiteLayout(full, 1.0, goal_distance, start_distance, 4, 11, "full.yaml"), InputError);
}

}  // namespace
}  // namespace trimbot::scenarios
