#include "runners/trial.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>

#include "evaluation/arm_reach.h"
#include "evaluation/trial_evaluator.h"
#include "evaluation/trim_evaluator.h"
#include "loop/closed_loop.h"
#include "loop/pilots.h"
#include "loop/prior_knowledge.h"
#include "loop/simulated_pose_fixes.h"
#include "reports/localization_timing.h"
#include "reports/output_files.h"
#include "reports/run_bag.h"
#include "reports/run_timing.h"
#include "reports/trial_video.h"
#include "reports/trim_plot.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/sim/simulator.h"
#include "trimbot/stack/robot_stack.h"

namespace trimbot::scenarios {
namespace {

// The navigator's costmap at the end: free white, the prior map grey, what only perception saw orange.
void WriteCostmapImage(const std::string& path, const cv::Mat& layers) {
  if (layers.empty()) return;
  cv::Mat image(layers.size(), CV_8UC3, cv::Scalar(248, 248, 244));
  image.setTo(cv::Scalar(90, 90, 90), layers == 128);
  image.setTo(cv::Scalar(215, 140, 70), layers == 255);
  WritePng(path, image, true);
}

// run.bag's frames (the robot as simulated) and the navigator's costmap.
RunBagOptions BagOptionsFor(const sim::Simulator& simulator, const stack::RobotStack& robot,
                            const garden::OccupancyMap& map) {
  RunBagOptions options;
  options.robot = &simulator.robot();
  for (const auto& camera : simulator.rig().cameras()) options.T_base_cameras.push_back(camera.T_base_camera);
  options.costmap = [&robot] { return robot.CostmapLayers(); };
  options.costmap_cells = map;
  return options;
}

// What a trial records beside its evaluation, as the setup asks: run.bag, trial.mp4.
struct TrialRecorders {
  std::optional<RunBag> bag;
  std::optional<TrialVideo> video;

  TrialRecorders(const TrialSetup& setup, sim::Simulator& simulator, const stack::RobotStack& robot) {
    if (setup.bag) bag.emplace(setup.dir + "/run.bag", BagOptionsFor(simulator, robot, setup.prepared->prior_map));
    if (setup.video) video.emplace(setup.dir + "/trial.mp4", simulator, setup.prepared->prior_map);
  }
  void AddTo(std::vector<Observer*>* observers) {
    if (bag) observers->push_back(&*bag);
    if (video) observers->push_back(&*video);
  }
  void Close() {
    if (bag) bag->Close();
    if (video) video->Close();
  }
};

// `render_for_stack`: the stack asks for the ring cameras it uses, when it uses them.
sim::SimulatorConfig PlantFor(const TrialSetup& setup, bool render_for_stack) {
  const Scenario& scenario = *setup.scenario;
  Setting setting = scenario.setting;
  setting.seed = setup.seed;
  sim::SimulatorConfig config = MakeSimulatorConfig(setup.paths, setting, setup.prepared->garden, setup.dir + "/world");
  config.render_cameras = scenario.render_cameras || render_for_stack;
  config.cameras_on_schedule = !render_for_stack;
  config.resolution_scale = scenario.resolution_scale;
  config.faults = scenario.faults;
  config.extra_objects = scenario.survey.unmapped_objects;
  config.imu_noise_scale = scenario.imu_noise_scale;
  config.wheel_slip_scale = scenario.wheel_slip_scale;
  config.motion_blur = scenario.motion_blur;
  config.camera_time_offset = CameraImuTimeOffset(scenario.calibration_error);
  config.cuttable_objects = TrimBushes(scenario);
  return config;
}

// A view of each trim bush from above, 60 deg round from the side the robot starts on (the robot
// comes between the bush and a view from that side).
std::vector<cv::Mat> RenderTrimBushes(sim::Simulator& simulator, const Scenario& scenario) {
  std::vector<cv::Mat> views;
  for (const int bush : TrimBushes(scenario)) {
    const Eigen::Vector3d centre = simulator.foliage(bush)->pose().translation();
    const Eigen::Vector2d towards =
        centre.head<2>() - Eigen::Vector2d(scenario.setting.start.x, scenario.setting.start.y);
    const double azimuth = std::atan2(towards.y(), towards.x()) * 180.0 / M_PI + 60.0;
    views.push_back(simulator.RenderExternalView(centre, 2.2, azimuth, -35.0, 640, 480));
  }
  return views;
}

// Per trim bush: the foliage (PLY), its distance to the target before and after, the views.
void WriteTrimFiles(const std::string& dir, const TrimEvaluator& evaluator, sim::Simulator& simulator,
                    const Scenario& scenario, const std::vector<cv::Mat>& views_before) {
  evaluator.WriteFiles(dir);
  const std::vector<int> bushes = TrimBushes(scenario);
  const std::vector<cv::Mat> views_after = RenderTrimBushes(simulator, scenario);
  for (std::size_t k = 0; k < bushes.size(); ++k) {
    const std::string id = std::to_string(bushes[k]);
    WriteTrimDistanceMap(dir + "/trim_" + id + "_distance.png", evaluator.before(bushes[k]),
                         *simulator.foliage(bushes[k]));
    WriteBeforeAfter(dir + "/trim_" + id + "_views.png", views_before[k], views_after[k]);
  }
}

// `bag_seconds`: wall time spent writing run.bag (inside the loop's figures), -1 without one.
void WriteTiming(const std::string& dir, const RunTiming& run, const stack::StackTimings& t, const TrialResult& result,
                 double bag_seconds = -1.0) {
  nlohmann::json timing = ToJson(run);
  if (bag_seconds >= 0.0) timing["run_bag_seconds"] = bag_seconds;
  if (!result.arm_planning_seconds.empty()) timing["arm_planning_seconds"] = result.arm_planning_seconds;
  if (!result.trim_timings.empty()) timing["trims"] = result.trim_timings;
  if (!t.plans.empty()) timing["navigation_planning_seconds"] = t.plans;
  WriteRunTimingChart(dir + "/timing.png", "where the trial's time went", run);
  if (!t.visual_frames.empty()) {
    timing["visual_localization"] = LocalizationTimeStats(t.visual_frames);
    WriteLocalizationTimeHistogram(dir + "/localization_time.png", "visual localization time per frame, this trial",
                                   t.visual_frames);
  }
  WriteFileAtomically(dir + "/timing.json", timing.dump(2));
}

// An arm_reach trial: the base stands at the start while the arm reaches the generated cutter poses.
TrialResult RunArmReachTrial(const TrialSetup& setup, const std::function<void(double)>& progress) {
  const Scenario& scenario = *setup.scenario;
  const ArmReach& spec = *scenario.arm_reach;
  const auto wall_start = std::chrono::steady_clock::now();
  TrialResult result;
  result.index = setup.index;
  result.seed = setup.seed;
  robot::RobotFiles files = setup.paths.robot_files();
  files.camchain = StackCalibration(scenario, setup.paths, setup.dir);
  const stack::StackParameters& parameters = setup.prepared->stack_parameters;
  sim::Simulator simulator(PlantFor(setup, /*render_for_stack=*/true));
  const Eigen::Isometry3d T_map_base = simulator.ground_truth().T_map_base;
  ArmCollisionTruth truth = MakeArmCollisionTruth(scenario, simulator, T_map_base);
  const std::vector<ArmReachPose> poses =
      GenerateArmReachPoses(scenario, truth, simulator.robot(), T_map_base, setup.seed);

  stack::RobotStack robot(files, parameters, setup.seed);
  robot.SetInitialPose(0.0, BelievedStart(scenario, setup.seed));
  std::vector<Eigen::Isometry3d> goals;
  for (const ArmReachPose& pose : poses) goals.push_back(pose.cutter_base);
  robot.SetArmGoals(goals);
  // A view across the robot and the bush at the first poses reached.
  int rendered = 0;
  const Eigen::Vector3d across = truth.bush_centre - T_map_base.translation();
  const double view_azimuth = std::atan2(across.y(), across.x()) * 180.0 / M_PI + 90.0;
  const auto render = [&](int goal) {
    if (rendered >= spec.renders) return;
    ++rendered;
    const Eigen::Vector3d lookat = 0.5 * (T_map_base.translation() + truth.bush_centre) + Eigen::Vector3d(0, 0, 0.3);
    char name[32];
    std::snprintf(name, sizeof(name), "/arm_pose_%02d.png", goal);
    WritePng(setup.dir + name, simulator.RenderExternalView(lookat, 2.6, view_azimuth, -20.0, 800, 600), true);
  };
  ArmReachEvaluator evaluator(spec, poses, &truth, render);
  StackPilot pilot(robot);
  LoopOptions options;
  options.time_limit = scenario.time_limit;
  options.render_on_demand = true;
  options.progress = progress;
  const auto loop_start = std::chrono::steady_clock::now();
  const bool finished = RunClosedLoop(simulator, pilot, {&evaluator}, options);
  result.status = finished ? "completed" : "timeout";
  if (!finished) result.message = "time limit of " + std::to_string(scenario.time_limit) + " s reached";
  result.simulated_seconds = simulator.time();
  evaluator.Finish(&result);
  const auto report_start = std::chrono::steady_clock::now();
  evaluator.WriteFiles(setup.dir);
  WriteFileAtomically(setup.dir + "/result.json", nlohmann::json(result).dump(2));
  const auto seconds = [](auto from, auto to) { return std::chrono::duration<double>(to - from).count(); };
  const auto now = std::chrono::steady_clock::now();
  result.wall_seconds = seconds(wall_start, now);
  const RunTiming run =
      MakeRunTiming(result.wall_seconds, result.simulated_seconds, simulator.timings(), &robot.telemetry().timings,
                    seconds(wall_start, loop_start), seconds(report_start, now));
  WriteTiming(setup.dir, run, robot.telemetry().timings, result);
  return result;
}

}  // namespace

TrialResult RunTrial(const TrialSetup& setup, const std::function<void(double)>& progress) {
  const Scenario& scenario = *setup.scenario;
  if (scenario.arm_reach) {
    std::filesystem::create_directories(setup.dir);
    return RunArmReachTrial(setup, progress);
  }
  const auto wall_start = std::chrono::steady_clock::now();
  std::filesystem::create_directories(setup.dir);
  TrialResult result;
  result.index = setup.index;
  result.seed = setup.seed;
  for (const auto& fault : scenario.faults) result.faults.push_back(fault.Describe());

  // The robot's side, from its own files and what the operator knows; never from the simulator.
  robot::RobotFiles files = setup.paths.robot_files();
  files.camchain = StackCalibration(scenario, setup.paths, setup.dir);
  const stack::StackParameters& parameters = setup.prepared->stack_parameters;
  const bool visual = parameters.localization == stack::LocalizationSource::kVisual;
  const std::vector<stack::Goal>& mission = setup.prepared->mission;
  const bool uses_images = stack::RobotStack::UsesRingImages(parameters, mission);
  sim::Simulator simulator(PlantFor(setup, uses_images));
  stack::RobotStack robot(files, parameters, setup.seed);
  robot.SetInitialPose(0.0, BelievedStart(scenario, setup.seed));
  robot.SetMap(setup.map_yaml);
  if (visual) robot.SetVisualMap(scenario.visual_map);
  robot.SetGoals(mission);
  if (!scenario.cutting_path_database.empty()) robot.SetCuttingPathDatabase(scenario.cutting_path_database);

  std::optional<SimulatedPoseFixes> fixes;
  if (parameters.localization == stack::LocalizationSource::kSimulatedPoseFixes) {
    fixes.emplace(scenario.simulated_pose_fixes, setup.seed);
  }
  GoalCriteria criteria;
  criteria.tolerance = scenario.goal_tolerance;
  criteria.yaw_tolerance = scenario.goal_yaw_tolerance;
  criteria.bush_distance = scenario.bush_distance_tolerance;
  criteria.bush_bearing = scenario.bush_bearing_tolerance;
  criteria.arm_axis = simulator.robot().FramePose(robot::RobotFrames::kCameraRing).translation().head<2>();
  TrialEvaluator evaluator(setup.prepared->goal_truths, criteria,
                           std::max(scenario.simulated_pose_fixes.latency_max, parameters.visual.latency_max) + 1.0);
  const auto [outline_min, outline_max] = simulator.robot().BaseOutline();
  evaluator.MeasureClearance(setup.prepared->true_garden, setup.prepared->clearance_height, outline_min, outline_max);
  StackPilot pilot(robot);
  LoopOptions options;
  options.time_limit = scenario.time_limit;
  options.pose_fixes = fixes ? &*fixes : nullptr;
  options.render_on_demand = uses_images;
  options.progress = progress;
  TrimEvaluator trims(simulator, scenario);
  const std::vector<cv::Mat> trim_views = RenderTrimBushes(simulator, scenario);
  TrialRecorders recorders(setup, simulator, robot);
  std::vector<Observer*> observers{&evaluator, &trims};
  recorders.AddTo(&observers);
  const auto loop_start = std::chrono::steady_clock::now();
  const bool finished = RunClosedLoop(simulator, pilot, observers, options);
  recorders.Close();

  evaluator.Finish(finished, scenario.time_limit, robot.telemetry(), &result);
  trims.Finish(&result);
  result.simulated_seconds = simulator.time();
  const auto report_start = std::chrono::steady_clock::now();
  evaluator.WriteFiles(setup.dir);
  WriteTrimFiles(setup.dir, trims, simulator, scenario, trim_views);
  if (parameters.obstacles.enabled) WriteCostmapImage(setup.dir + "/costmap.png", robot.CostmapLayers());
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  WriteFileAtomically(setup.dir + "/result.json", nlohmann::json(result).dump(2));
  const auto seconds = [](auto from, auto to) { return std::chrono::duration<double>(to - from).count(); };
  const auto now = std::chrono::steady_clock::now();
  const RunTiming run =
      MakeRunTiming(seconds(wall_start, now), result.simulated_seconds, simulator.timings(), &robot.telemetry().timings,
                    seconds(wall_start, loop_start), seconds(report_start, now));
  WriteTiming(setup.dir, run, robot.telemetry().timings, result, recorders.bag ? recorders.bag->seconds() : -1.0);
  return result;
}

}  // namespace trimbot::scenarios
