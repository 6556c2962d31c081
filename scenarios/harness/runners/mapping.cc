#include "runners/mapping.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <random>

#include "evaluation/trial_result.h"
#include "loop/closed_loop.h"
#include "loop/drive_plan.h"
#include "loop/pilots.h"
#include "loop/prior_knowledge.h"
#include "loop/scenario.h"
#include "loop/simulated_pose_fixes.h"
#include "reports/map_plot.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/random.h"
#include "trimbot/common/rotation.h"
#include "trimbot/common/yaml_reader.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/stack/robot_stack.h"
#include "trimbot/visual_localization/map_builder.h"

namespace trimbot::scenarios {
namespace {

using Clock = std::chrono::steady_clock;

// The survey: each exposure's true pose with seeded noise, drawn once per exposure.
class SurveyPoses {
 public:
  SurveyPoses(std::uint64_t seed, double position_sigma, double rotation_sigma)
      : rng_(MakeRng(seed, "survey")), position_sigma_(position_sigma), rotation_sigma_(rotation_sigma) {}

  const Eigen::Isometry3d& PoseAt(const sim::GroundTruth& truth) {
    auto it = poses_.find(truth.stamp);
    if (it != poses_.end()) return it->second;
    Eigen::Isometry3d pose = truth.T_map_base;
    const auto dp = StandardNormalVector<Eigen::Vector3d>(rng_);
    const auto dr = StandardNormalVector<Eigen::Vector3d>(rng_);
    pose.translation() += position_sigma_ * dp;
    const Eigen::Vector3d w = rotation_sigma_ * dr;
    pose.linear() = RotationFromVector(w) * pose.linear();
    truth_[truth.stamp] = truth.T_map_base;
    return poses_.emplace(truth.stamp, pose).first->second;
  }
  const std::map<double, Eigen::Isometry3d>& truth() const { return truth_; }
  const std::map<double, Eigen::Isometry3d>& poses() const { return poses_; }

 private:
  Rng rng_;
  double position_sigma_, rotation_sigma_;
  std::map<double, Eigen::Isometry3d> poses_, truth_;
};

// Hands the rendered keyframes to the builder with their survey poses.
class MapRecorder : public Observer {
 public:
  MapRecorder(visual_localization::MapBuilder& builder, SurveyPoses& survey) : builder_(builder), survey_(survey) {}
  void Observe(const StepView& step) override {
    if (step.sensors.ring) builder_.AddFrame(*step.sensors.ring, survey_.PoseAt(step.truth));
  }

 private:
  visual_localization::MapBuilder& builder_;
  SurveyPoses& survey_;
};

// Mean position error (m) of the map's keyframes against the ground truth at their stamps.
nlohmann::json KeyframeErrors(const visual_localization::VisualMap& map, const SurveyPoses& survey) {
  std::vector<double> adjusted, surveyed;
  for (const auto& k : map.keyframes) {
    const auto truth = survey.truth().find(k.stamp);
    if (truth == survey.truth().end()) continue;
    adjusted.push_back((k.T_map_base.translation() - truth->second.translation()).norm());
    surveyed.push_back((survey.poses().at(k.stamp).translation() - truth->second.translation()).norm());
  }
  return {{"survey_position_error_mean_m", ErrorStats::From(surveyed).mean},
          {"adjusted_position_error_mean_m", ErrorStats::From(adjusted).mean}};
}

constexpr std::uint64_t kMappingSeedOffset = 1000;  // a scenario's mapping drive: other noise than its trials

// The mapping drive: a drive plan played open loop, or a scenario whose goals the robot drives to
// with its stack (navigating on the simulated fixes, or dead reckoning: the map does not exist yet).
struct MappingDrive {
  Setting setting;
  double duration = 0.0;
  std::optional<DrivePlan> plan;
  std::optional<Scenario> scenario;
  std::unique_ptr<stack::RobotStack> robot;
  std::unique_ptr<Pilot> pilot;
  std::optional<SimulatedPoseFixes> fixes;
  visual_localization::Descriptor descriptor;  // the stack's, whose localizer will use the map
};

std::unique_ptr<MappingDrive> LoadMappingDrive(const MapBuildOptions& options) {
  auto drive = std::make_unique<MappingDrive>();
  stack::StackParameters parameters = stack::StackParameters::Load(options.paths.robot_files().stack_parameters);
  drive->descriptor = parameters.visual.descriptor;
  if (!YamlMap::LoadFile(options.recipe.plan_path).Has("goals")) {
    drive->plan = DrivePlan::Load(options.recipe.plan_path);
    drive->setting = drive->plan->setting;
    if (options.recipe.seed) drive->setting.seed = *options.recipe.seed;
    drive->duration = std::min(drive->plan->duration(), options.recipe.seconds.value_or(drive->plan->duration()));
    drive->pilot = std::make_unique<DrivePlanPlayer>(*drive->plan, drive->duration);
    return drive;
  }
  drive->scenario = Scenario::Load(options.recipe.plan_path);
  const Scenario& scenario = *drive->scenario;
  drive->setting = scenario.setting;
  drive->setting.seed = options.recipe.seed.value_or(scenario.setting.seed + kMappingSeedOffset);
  drive->duration = std::min(scenario.time_limit, options.recipe.seconds.value_or(scenario.time_limit));
  if (scenario.stack) parameters = parameters.Overridden(*scenario.stack);
  drive->descriptor = parameters.visual.descriptor;
  if (parameters.localization == stack::LocalizationSource::kVisual) {
    parameters.localization = stack::LocalizationSource::kSimulatedPoseFixes;
  }
  drive->robot = std::make_unique<stack::RobotStack>(options.paths.robot_files(), parameters, drive->setting.seed);
  drive->robot->SetInitialPose(0.0, scenario.setting.start);
  const garden::Garden surveyed =
      SurveyedGarden(LoadGarden(scenario.setting, options.paths), scenario.survey, scenario.source);
  drive->robot->SetMap(WritePriorMap(PriorMap(scenario, surveyed), options.out_dir + "/prior_map"));
  drive->robot->SetGoals(MissionGoals(scenario, surveyed));
  if (parameters.localization == stack::LocalizationSource::kSimulatedPoseFixes) {
    drive->fixes.emplace(scenario.simulated_pose_fixes, drive->setting.seed);
  }
  drive->pilot = std::make_unique<StackPilot>(*drive->robot);
  return drive;
}

}  // namespace

visual_localization::MapBuilderOptions MapBuilderOptionsFor(const MapRecipe& recipe,
                                                            visual_localization::Descriptor descriptor) {
  visual_localization::MapBuilderOptions options;
  options.survey_position_sigma = recipe.survey_position_sigma;
  options.survey_rotation_sigma = recipe.survey_rotation_sigma_deg * M_PI / 180.0;
  options.features.descriptor = descriptor;
  return options;
}

int RunMapBuild(const MapBuildOptions& options) {
  const auto wall_start = Clock::now();
  std::filesystem::create_directories(options.out_dir);
  const std::unique_ptr<MappingDrive> drive = LoadMappingDrive(options);
  const Setting& setting = drive->setting;
  sim::SimulatorConfig config =
      MakeSimulatorConfig(options.paths, setting, LoadGarden(setting, options.paths), options.out_dir + "/world");
  config.cameras_on_schedule = false;  // only the keyframes are rendered
  sim::Simulator simulator(config);

  // The map is made with the calibration the robot's stack reads (robot/), as the real one was.
  const robot::CameraRig rig = robot::LoadCameraRig(options.paths.robot_files());
  const visual_localization::MapBuilderOptions builder_options =
      MapBuilderOptionsFor(options.recipe, options.recipe.descriptor.value_or(drive->descriptor));
  visual_localization::MapBuilder builder(rig, builder_options);
  SurveyPoses survey(setting.seed, builder_options.survey_position_sigma, builder_options.survey_rotation_sigma);

  MapRecorder recorder(builder, survey);
  LoopOptions loop;
  loop.time_limit = drive->duration;
  loop.render_on_demand = true;
  loop.ring_demand = [&](const sim::GroundTruth& truth) { return builder.WantsFrame(survey.PoseAt(truth)); };
  loop.pose_fixes = drive->fixes ? &*drive->fixes : nullptr;
  // Progress every 10 simulated seconds: a mapping drive renders for minutes.
  loop.progress = [&](double t) {
    if (static_cast<int>(t) % 10 != 0) return;
    std::cout << "[map] " << static_cast<int>(t) << "/" << static_cast<int>(drive->duration) << " s driven, "
              << builder.keyframes() << " keyframes, "
              << static_cast<int>(std::chrono::duration<double>(Clock::now() - wall_start).count()) << " s elapsed"
              << std::endl;
  };
  std::cout << "[map] driving " << options.recipe.plan_path << " (up to " << drive->duration
            << " s), rendering keyframes" << std::endl;
  RunClosedLoop(simulator, *drive->pilot, {&recorder}, loop);
  const double drive_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();

  std::cout << "[map] drive done, " << builder.keyframes() << " keyframes in " << static_cast<int>(drive_seconds)
            << " s; features, matching, bundle adjustment..." << std::endl;
  visual_localization::MapBuildStats stats;
  const visual_localization::VisualMap map = builder.Build(simulator.garden().name, &stats);
  if (map.points.empty()) {
    throw std::runtime_error(options.recipe.plan_path + ": the mapping drive gave no map points (" +
                             std::to_string(stats.keyframes) + " keyframes; too short, or nothing textured in view)");
  }
  map.Save(options.out_dir + "/map.sqlite");
  const garden::OccupancyMap objects = garden::MakeOccupancyMap(simulator.garden(), 0.05, 1.0);
  WriteMapTopView(options.out_dir + "/map_top_view.png", map, objects,
                  "map of " + map.garden + ": " + std::to_string(stats.points) + " points, " +
                      std::to_string(stats.keyframes) + " keyframes");
  const double total_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  nlohmann::json report = {{"plan", options.recipe.plan_path},
                           {"garden", map.garden},
                           {"seed", setting.seed},
                           {"descriptor", visual_localization::ToString(map.descriptor)},
                           {"frames_seen", stats.frames},
                           {"keyframes", stats.keyframes},
                           {"images_matched", stats.images_matched},
                           {"matches", stats.matches},
                           {"tracks", stats.tracks},
                           {"points", stats.points},
                           {"observations", stats.observations},
                           {"outlier_observations_dropped", stats.outlier_observations},
                           {"mean_track_length", stats.mean_track_length},
                           {"reprojection_rmse_px", stats.reprojection_rmse_px},
                           {"seconds",
                            {{"drive_and_render", drive_seconds - stats.seconds_features},
                             {"features", stats.seconds_features},
                             {"matching", stats.seconds_matching},
                             {"adjustment", stats.seconds_adjustment},
                             {"vocabulary", stats.seconds_vocabulary},
                             {"total", total_seconds}}},
                           {"keyframes_against_ground_truth", KeyframeErrors(map, survey)}};
  WriteFileAtomically(options.out_dir + "/map_stats.json", report.dump(2));
  std::cout << "[map] " << stats.keyframes << " keyframes, " << stats.points << " points, mean track "
            << stats.mean_track_length << ", reprojection RMSE " << stats.reprojection_rmse_px << " px, "
            << total_seconds << " s -> " << options.out_dir << "/map.sqlite" << std::endl;
  return 0;
}

}  // namespace trimbot::scenarios
