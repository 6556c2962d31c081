#include "runners/mapping.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>

#include "evaluation/map_evaluation.h"
#include "evaluation/trial_result.h"
#include "evaluation/tum_trajectory.h"
#include "loop/closed_loop.h"
#include "loop/drive_plan.h"
#include "loop/drive_recording.h"
#include "loop/pilots.h"
#include "loop/prior_knowledge.h"
#include "loop/scenario.h"
#include "loop/simulated_pose_fixes.h"
#include "reports/map_plot.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/random.h"
#include "trimbot/common/rotation.h"
#include "trimbot/common/yaml_reader.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/garden/textures.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/robot/robot_parameters.h"
#include "trimbot/stack/inertial_odometry.h"
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
class SurveyRecorder : public Observer {
 public:
  SurveyRecorder(visual_localization::MapBuilder& builder, SurveyPoses& survey) : builder_(builder), survey_(survey) {}
  void Observe(const StepView& step) override {
    if (step.sensors.ring) builder_.AddFrame(*step.sensors.ring, survey_.PoseAt(step.truth));
  }

 private:
  visual_localization::MapBuilder& builder_;
  SurveyPoses& survey_;
};

// The robot's own log: its IMU and wheels feed the wheel-inertial odometry, whose pose each
// rendered keyframe gets. The true pose at each keyframe's stamp is recorded beside it for the
// evaluation only; the builder never sees it.
class LogRecorder : public Observer {
 public:
  LogRecorder(visual_localization::MapBuilder& builder, stack::InertialOdometry& odometry)
      : builder_(builder), odometry_(odometry) {}
  // Whether the builder wants the ring rendered now (asked before the step's sensors arrive).
  bool Demand() {
    demanded_ = builder_.WantsFrame(ToIsometry(odometry_.pose()));
    return demanded_;
  }
  void Observe(const StepView& step) override {
    for (const auto& imu : step.sensors.imu) odometry_.Add(imu);
    for (const auto& ticks : step.sensors.wheel_ticks) odometry_.Add(ticks);
    // Only a ring the builder asked for is whole (a stack may ask for a few cameras of others).
    if (step.sensors.ring && demanded_ && builder_.AddFrame(*step.sensors.ring, ToIsometry(odometry_.pose()))) {
      truth_.push_back({step.sensors.ring->stamp, step.truth.T_map_base});
    }
    demanded_ = false;
  }
  const std::vector<StampedPose>& truth() const { return truth_; }

 private:
  visual_localization::MapBuilder& builder_;
  stack::InertialOdometry& odometry_;
  std::vector<StampedPose> truth_;  // evaluation only
  bool demanded_ = false;
};

// Mean position error (m) of the map's keyframes against the ground truth at their exposures
// (the images' stamps are `camera_time_offset` s after them).
nlohmann::json KeyframeErrors(const visual_localization::VisualMap& map, const SurveyPoses& survey,
                              double camera_time_offset) {
  std::vector<double> adjusted, surveyed;
  for (const auto& k : map.keyframes) {
    const auto truth = survey.truth().lower_bound(k.stamp - camera_time_offset - 1e-6);
    if (truth == survey.truth().end() || truth->first > k.stamp - camera_time_offset + 1e-6) continue;
    adjusted.push_back((k.T_map_base.translation() - truth->second.translation()).norm());
    surveyed.push_back((survey.poses().at(truth->first).translation() - truth->second.translation()).norm());
  }
  return {{"survey_position_error_mean_m", ErrorStats::From(surveyed).mean},
          {"adjusted_position_error_mean_m", ErrorStats::From(adjusted).mean}};
}

constexpr double kSurfaceSamplesPerM2 = 10000.0;  // 1 cm apart: the point error is resolved to a few mm

// A log-built map against the truth: keyframes (and the odometry they started from), points
// against the garden's true surfaces; TUM files of all three trajectories for evo.
nlohmann::json EvaluateLogMap(const visual_localization::MapBuilder& builder, const visual_localization::VisualMap& map,
                              const std::vector<StampedPose>& truth, const garden::Garden& garden, double growth,
                              const std::string& out_dir) {
  std::vector<StampedPose> estimate, odometry;
  std::string tum_estimate, tum_odometry, tum_truth;
  for (std::size_t k = 0; k < builder.keyframe_data().size(); ++k) {
    const auto& keyframe = builder.keyframe_data()[k];
    estimate.push_back({keyframe.stamp, keyframe.T_map_base});
    odometry.push_back({keyframe.stamp, keyframe.T_prior});
    tum_estimate += TumLine(keyframe.stamp, keyframe.T_map_base);
    tum_odometry += TumLine(keyframe.stamp, keyframe.T_prior);
    tum_truth += TumLine(truth[k].stamp, truth[k].T);
  }
  WriteFileAtomically(out_dir + "/keyframes.tum", tum_estimate);
  WriteFileAtomically(out_dir + "/keyframes_odometry.tum", tum_odometry);
  WriteFileAtomically(out_dir + "/keyframes_truth.tum", tum_truth);
  std::string loops = "query,match,inliers,weight\n";
  for (const auto& loop : builder.loops()) {
    loops += std::to_string(loop.query) + "," + std::to_string(loop.match) + "," + std::to_string(loop.inliers) + "," +
             std::to_string(loop.weight) + "\n";
  }
  WriteFileAtomically(out_dir + "/loops.csv", loops);
  std::vector<Eigen::Vector3d> surface;
  for (const auto& sample : garden::SampleSurfaces(garden, growth, kSurfaceSamplesPerM2))
    surface.push_back(sample.position);
  return {{"keyframes", TrajectoryErrors(estimate, truth)},
          {"odometry", TrajectoryErrors(odometry, truth)},
          {"points_to_true_surfaces_m", PointErrors(map.points, surface)}};
}

// The surveyed objects as shapes, for the tie of a log-built map to the garden.
std::vector<visual_localization::SurveyedShape> SurveyedShapes(const garden::Garden& surveyed) {
  using Kind = visual_localization::SurveyedShape::Kind;
  std::vector<visual_localization::SurveyedShape> shapes;
  for (const auto& object : surveyed.objects) {
    // A trunk is rendered as a cylinder whatever its surveyed shape (object_mesh.cc).
    const Kind kind = object.object_class == garden::ObjectClass::kTrunk ? Kind::kCylinder
                      : object.shape == garden::Shape::kBox              ? Kind::kBox
                      : object.shape == garden::Shape::kCylinder         ? Kind::kCylinder
                                                                         : Kind::kEllipsoid;
    const Eigen::Vector3d centre(object.position.x(), object.position.y(), object.base_height + object.size.z() / 2);
    shapes.push_back({kind, centre, object.size, object.yaw});
  }
  return shapes;
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
  stack::EkfParameters ekf;                    // the stack's, for the log builder's odometry
  Pose2 believed_start;     // where the robot is believed to start (the stated start, put down with an error)
  garden::Garden surveyed;  // the garden as the user surveyed it (its errors included)
};

// What the user knows of a drive plan's drive (played, or recorded): the stated start, put down
// near, not at, it; the plan's garden surveyed once with the default survey, seeded by the drive's
// seed.
struct KnownStart {
  Pose2 believed_start;
  garden::Garden surveyed;
};
KnownStart KnownFromPlan(const Setting& setting, const garden::Garden& built, const std::string& source) {
  Survey survey;
  survey.seed = setting.seed;
  return {BelievedPose(setting.start, kInitialPositionSigma, kInitialYawSigma, setting.seed),
          SurveyedGarden(built, survey, source)};
}

// The camera calibration the robot's stack reads (the rendering uses the true one).
robot::CameraRig StackCameraRig(const MapBuildOptions& options) {
  return CalibratedRig(robot::LoadCameraRig(options.paths.robot_files()), options.recipe.calibration_error);
}

// The log builder's odometry: the robot's IMU and wheel ticks, from the believed start.
stack::InertialOdometry LogOdometry(const ProjectPaths& paths, const stack::EkfParameters& ekf,
                                    const Pose2& believed_start) {
  const robot::RobotDescription description = robot::RobotDescription::Load(paths.robot_files().urdf);
  return stack::InertialOdometry(
      ekf, description.drive(),
      robot::RobotParameters::Load(paths.robot_files().robot_parameters).wheel_encoders.ticks_per_revolution, 0.0,
      believed_start);
}

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
    drive->ekf = parameters.ekf;
    KnownStart known =
        KnownFromPlan(drive->setting, LoadGarden(drive->setting, options.paths), options.recipe.plan_path);
    drive->believed_start = known.believed_start;
    drive->surveyed = std::move(known.surveyed);
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
  drive->ekf = parameters.ekf;
  drive->believed_start = BelievedStart(scenario, drive->setting.seed);
  drive->robot->SetInitialPose(0.0, drive->believed_start);
  drive->surveyed = SurveyedGarden(LoadGarden(scenario.setting, options.paths), scenario.survey, scenario.source);
  drive->robot->SetMap(WritePriorMap(PriorMap(scenario, drive->surveyed, MapClearanceHeight(scenario, options.paths)),
                                     options.out_dir + "/prior_map"));
  drive->robot->SetGoals(MissionGoals(scenario, drive->surveyed));
  if (parameters.localization == stack::LocalizationSource::kSimulatedPoseFixes) {
    drive->fixes.emplace(scenario.simulated_pose_fixes, drive->setting.seed);
  }
  drive->pilot = std::make_unique<StackPilot>(*drive->robot);
  return drive;
}

// The build's figures (map_stats.json); `drive_seconds` includes the features' extraction.
nlohmann::json MapStats(const std::string& plan_path, std::uint64_t seed, const char* builder,
                        const visual_localization::VisualMap& map, const visual_localization::MapBuildStats& stats,
                        double drive_seconds, double total_seconds) {
  return {{"plan", plan_path},
          {"garden", map.garden},
          {"seed", seed},
          {"descriptor", visual_localization::ToString(map.descriptor)},
          {"builder", builder},
          {"frames_seen", stats.frames},
          {"keyframes", stats.keyframes},
          {"images_matched", stats.images_matched},
          {"matches", stats.matches},
          {"tracks", stats.tracks},
          {"points", stats.points},
          {"observations", stats.observations},
          {"outlier_observations_dropped", stats.outlier_observations},
          {"mean_track_length", stats.mean_track_length},
          {"gaps", {{"count", stats.gaps.size()}, {"keyframes", stats.gaps}}},
          {"reprojection_rmse_px", stats.reprojection_rmse_px},
          {"seconds",
           {{"drive_and_render", drive_seconds - stats.seconds_features},
            {"features", stats.seconds_features},
            {"matching", stats.seconds_matching},
            {"loops", stats.seconds_loops},
            {"adjustment", stats.seconds_adjustment},
            {"vocabulary", stats.seconds_vocabulary},
            {"total", total_seconds}}}};
}

// The log builder's own figures: stereo, loops, wheel scales, the tie to the surveyed garden.
nlohmann::json LogBuildStats(const visual_localization::MapBuildStats& stats, std::size_t loops_found) {
  return {{"stereo_matches", stats.stereo_matches},
          {"single_keyframe_tracks_dropped", stats.single_keyframe_tracks},
          {"loops_tried", stats.loops_tried},
          {"loops_found", loops_found},
          {"loops_accepted", stats.loops_accepted},
          {"wheel_scale_stretches", stats.scale_stretches},
          {"wheel_scale_min", stats.scale_min},
          {"wheel_scale_max", stats.scale_max},
          {"tie_points", stats.tie_points},
          {"tie_residual_median_m", stats.tie_residual_median},
          {"tie_correction",
           {{"x_m", stats.tie_correction.x()},
            {"y_m", stats.tie_correction.y()},
            {"yaw_deg", stats.tie_correction.z() * 180 / M_PI}}}};
}

}  // namespace

visual_localization::MapBuilderOptions MapBuilderOptionsFor(const MapRecipe& recipe,
                                                            visual_localization::Descriptor descriptor) {
  visual_localization::MapBuilderOptions options;
  options.survey_position_sigma = recipe.survey_position_sigma;
  options.survey_rotation_sigma = recipe.survey_rotation_sigma_deg * M_PI / 180.0;
  options.features.descriptor = descriptor;
  options.poses = recipe.builder;
  return options;
}

// The mapping drive's simulator: only the keyframes are rendered; the robot's cameras keep their
// clock offset.
sim::SimulatorConfig MappingSimulatorConfig(const MapBuildOptions& options, const Setting& setting) {
  sim::SimulatorConfig config =
      MakeSimulatorConfig(options.paths, setting, LoadGarden(setting, options.paths), options.out_dir + "/world");
  config.cameras_on_schedule = false;
  config.camera_time_offset = CameraImuTimeOffset(options.recipe.calibration_error);
  return config;
}

namespace {

// The build's end, whatever the drive: bundle adjustment, map.sqlite, the top view and
// map_stats.json, with what `evaluate` adds (timed as the evaluation).
int FinishMapBuild(const MapBuildOptions& options, visual_localization::MapBuilder& builder,
                   const garden::Garden& garden, std::uint64_t seed, double drive_seconds, Clock::time_point wall_start,
                   const std::function<void(nlohmann::json&, const visual_localization::VisualMap&,
                                            const visual_localization::MapBuildStats&)>& evaluate) {
  std::cout << "[map] drive done, " << builder.keyframes() << " keyframes in " << static_cast<int>(drive_seconds)
            << " s; features, matching, bundle adjustment..." << std::endl;
  visual_localization::MapBuildStats stats;
  visual_localization::VisualMap map = builder.Build(garden.name, &stats);
  map.appearance_version = garden::kTextureGeneratorVersion;
  if (map.points.empty()) {
    throw std::runtime_error(options.recipe.plan_path + ": the mapping drive gave no map points (" +
                             std::to_string(stats.keyframes) + " keyframes; too short, or nothing textured in view)");
  }
  map.Save(options.out_dir + "/map.sqlite");
  const garden::OccupancyMap objects = garden::MakeOccupancyMap(garden, 0.05, 1.0);
  WriteMapTopView(options.out_dir + "/map_top_view.png", map, objects,
                  "map of " + map.garden + ": " + std::to_string(stats.points) + " points, " +
                      std::to_string(stats.keyframes) + " keyframes");
  const double total_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  nlohmann::json report =
      MapStats(options.recipe.plan_path, seed, visual_localization::ToString(options.recipe.builder), map, stats,
               drive_seconds, total_seconds);
  const auto evaluation_start = Clock::now();
  evaluate(report, map, stats);
  report["seconds"]["evaluation"] = std::chrono::duration<double>(Clock::now() - evaluation_start).count();
  WriteFileAtomically(options.out_dir + "/map_stats.json", report.dump(2));
  std::cout << "[map] " << stats.keyframes << " keyframes, " << stats.points << " points, mean track "
            << stats.mean_track_length << ", reprojection RMSE " << stats.reprojection_rmse_px << " px, "
            << total_seconds << " s -> " << options.out_dir << "/map.sqlite" << std::endl;
  return 0;
}

// The true base pose nearest to each stamp (the recording's base.tum has one per physics step).
std::vector<StampedPose> TruthAt(const std::vector<StampedPose>& truth, const std::vector<double>& stamps) {
  std::vector<StampedPose> nearest;
  for (const double stamp : stamps) {
    auto after = std::lower_bound(truth.begin(), truth.end(), stamp,
                                  [](const StampedPose& pose, double t) { return pose.stamp < t; });
    if (after == truth.end() || (after != truth.begin() && stamp - std::prev(after)->stamp < after->stamp - stamp)) {
      --after;
    }
    nearest.push_back(*after);
  }
  return nearest;
}

// A map from a recorded drive (a `trimbot drive` folder): its IMU and wheel ticks replayed through
// the wheel-inertial odometry, its saved ring frames offered to the builder at their stamps, the
// garden as surveyed (seeded by the drive's seed) for the tie. Saved frames that cannot be read are
// gaps, reported; the recording's ground truth (ground_truth/base.tum) goes to the evaluation only.
int RunMapBuildFromRecording(const MapBuildOptions& options) {
  const auto wall_start = Clock::now();
  const std::string& dir = options.recipe.plan_path;
  if (options.recipe.builder != visual_localization::KeyframePoses::kOdometry) {
    throw InputError(dir, "a recorded drive is built from its log (--builder log): survey poses need the truth");
  }
  const DriveRecording recording = DriveRecording::Load(dir);
  Setting setting = recording.plan().setting;
  if (options.recipe.seed) setting.seed = *options.recipe.seed;
  const double until = options.recipe.seconds.value_or(std::numeric_limits<double>::infinity());
  std::filesystem::create_directories(options.out_dir);
  const stack::StackParameters parameters = stack::StackParameters::Load(options.paths.robot_files().stack_parameters);
  const robot::CameraRig rig = StackCameraRig(options);
  visual_localization::MapBuilder builder(
      rig, MapBuilderOptionsFor(options.recipe, options.recipe.descriptor.value_or(parameters.visual.descriptor)));
  const garden::Garden garden = LoadGarden(setting, options.paths);
  const KnownStart known = KnownFromPlan(setting, garden, recording.plan().source);
  builder.SetSurveyedShapes(SurveyedShapes(known.surveyed));
  stack::InertialOdometry odometry = LogOdometry(options.paths, parameters.ekf, known.believed_start);

  std::cout << "[map] replaying " << dir << ": " << recording.frames().size() << " ring frames" << std::endl;
  std::vector<double> keyframe_stamps;
  std::vector<std::string> gaps;
  std::size_t next_imu = 0, next_ticks = 0;
  const auto& imu = recording.imu();
  const auto& ticks = recording.wheel_ticks();
  for (const RecordedRingFrame& frame : recording.frames()) {
    if (frame.stamp > until) break;
    // The sensors up to the frame, in the order they arrived.
    while ((next_imu < imu.size() && imu[next_imu].stamp <= frame.stamp) ||
           (next_ticks < ticks.size() && ticks[next_ticks].stamp <= frame.stamp)) {
      const bool imu_first = next_ticks >= ticks.size() || ticks[next_ticks].stamp > frame.stamp ||
                             (next_imu < imu.size() && imu[next_imu].stamp <= ticks[next_ticks].stamp);
      if (imu_first) {
        odometry.Add(imu[next_imu++]);
      } else {
        odometry.Add(ticks[next_ticks++]);
      }
    }
    const Eigen::Isometry3d pose = ToIsometry(odometry.pose());
    if (!frame.saved || !builder.WantsFrame(pose)) continue;
    std::string gap;
    const auto ring =
        recording.LoadFrame(frame, rig.size(), rig.camera(0).intrinsics.width, rig.camera(0).intrinsics.height, &gap);
    if (!ring) {
      gaps.push_back(gap);
      continue;
    }
    if (builder.AddFrame(*ring, pose)) keyframe_stamps.push_back(frame.stamp);
  }
  const double drive_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  const std::string truth_path = dir + "/ground_truth/base.tum";
  return FinishMapBuild(options, builder, garden, setting.seed, drive_seconds, wall_start,
                        [&](nlohmann::json& report, const visual_localization::VisualMap& map,
                            const visual_localization::MapBuildStats& stats) {
                          report["log"] = LogBuildStats(stats, builder.loops().size());
                          report["log"]["frames_unreadable"] = gaps;
                          if (!std::filesystem::exists(truth_path)) {
                            report["evaluation"] = "none: the recording has no ground_truth/base.tum";
                            return;
                          }
                          report["evaluation"] =
                              EvaluateLogMap(builder, map, TruthAt(ReadTum(truth_path), keyframe_stamps), garden,
                                             setting.conditions.growth, options.out_dir);
                        });
}

}  // namespace

int RunMapBuild(const MapBuildOptions& options) {
  if (std::filesystem::is_directory(options.recipe.plan_path)) return RunMapBuildFromRecording(options);
  const auto wall_start = Clock::now();
  std::filesystem::create_directories(options.out_dir);
  const std::unique_ptr<MappingDrive> drive = LoadMappingDrive(options);
  const Setting& setting = drive->setting;
  sim::Simulator simulator(MappingSimulatorConfig(options, setting));

  // The map is made with the calibration the robot's stack reads, as the real one was.
  const robot::CameraRig rig = StackCameraRig(options);
  const visual_localization::MapBuilderOptions builder_options =
      MapBuilderOptionsFor(options.recipe, options.recipe.descriptor.value_or(drive->descriptor));
  visual_localization::MapBuilder builder(rig, builder_options);
  const bool from_log = builder_options.poses == visual_localization::KeyframePoses::kOdometry;
  SurveyPoses survey(setting.seed, builder_options.survey_position_sigma, builder_options.survey_rotation_sigma);
  stack::InertialOdometry odometry = LogOdometry(options.paths, drive->ekf, drive->believed_start);
  if (from_log) builder.SetSurveyedShapes(SurveyedShapes(drive->surveyed));
  SurveyRecorder survey_recorder(builder, survey);
  LogRecorder log_recorder(builder, odometry);
  Observer& recorder = from_log ? static_cast<Observer&>(log_recorder) : survey_recorder;

  LoopOptions loop;
  loop.time_limit = drive->duration;
  loop.render_on_demand = true;
  loop.ring_demand = [&](const sim::GroundTruth& truth) {
    return from_log ? log_recorder.Demand() : builder.WantsFrame(survey.PoseAt(truth));
  };
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
  const double growth = setting.conditions.growth;
  return FinishMapBuild(options, builder, simulator.garden(), setting.seed, drive_seconds, wall_start,
                        [&](nlohmann::json& report, const visual_localization::VisualMap& map,
                            const visual_localization::MapBuildStats& stats) {
                          if (from_log) {
                            report["log"] = LogBuildStats(stats, builder.loops().size());
                            report["evaluation"] = EvaluateLogMap(builder, map, log_recorder.truth(),
                                                                  simulator.garden(), growth, options.out_dir);
                          } else {
                            report["keyframes_against_ground_truth"] =
                                KeyframeErrors(map, survey, CameraImuTimeOffset(options.recipe.calibration_error));
                          }
                        });
}

}  // namespace trimbot::scenarios
