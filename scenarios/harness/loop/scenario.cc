#include "loop/scenario.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include "trimbot/common/yaml_reader.h"

namespace trimbot::scenarios {
namespace {

Eigen::Vector3d OptionalVector3(const YamlMap& map, const std::string& key, double limit, const std::string& unit) {
  if (!map.Has(key)) return Eigen::Vector3d::Zero();
  const auto v = map.Numbers(key, 3, -limit, limit, unit);
  return {v[0], v[1], v[2]};
}

sim::Fault ReadFault(const YamlMap& item) {
  sim::Fault fault;
  const std::string type = item.String("type");
  if (type == "wheel_slip") {
    fault.kind = sim::Fault::Kind::kWheelSlip;
    fault.start = item.Number("start", 0.0, 1e6, "s");
    fault.duration = item.Number("duration", 1e-3, 1e6, "s");
    // A slip of -1 would stop the wheel's travel entirely; more than 10 times the travel is no slip.
    fault.slip_left = item.NumberOr("left", 0.0, -0.99, 10.0);
    fault.slip_right = item.NumberOr("right", 0.0, -0.99, 10.0);
  } else if (type == "imu_bias_jump") {
    fault.kind = sim::Fault::Kind::kImuBiasJump;
    fault.start = item.Number("time", 0.0, 1e6, "s");
    fault.gyroscope_bias_jump = OptionalVector3(item, "gyro", 10.0, "rad/s");
    fault.accelerometer_bias_jump = OptionalVector3(item, "accel", 100.0, "m/s^2");
  } else if (type == "camera_dropout") {
    fault.kind = sim::Fault::Kind::kCameraDropout;
    fault.start = item.Number("start", 0.0, 1e6, "s");
    fault.duration = item.Number("duration", 1e-3, 1e6, "s");
  } else {
    item.Fail("type", "unknown fault '" + type + "' (wheel_slip, imu_bias_jump, camera_dropout)");
  }
  item.RejectUnknownKeys();
  return fault;
}

SimulatedPoseFixParameters ReadSimulatedPoseFixes(const YamlMap& map) {
  SimulatedPoseFixParameters p;
  p.availability = map.NumberOr("availability", p.availability, 0.0, 1.0);
  p.outage_mean_duration = map.NumberOr("outage_mean_duration", p.outage_mean_duration, 0.0, 3600.0, "s");
  // The fixes state their covariance from these, and the EKF refuses a fix whose covariance is not
  // positive definite: zero would have every fix refused (the drive on odometry alone), so the
  // least is a millimetre and a hundredth of a degree.
  p.position_sigma = map.NumberOr("position_sigma", p.position_sigma, 1e-3, 100.0, "m");
  p.yaw_sigma = map.NumberOr("yaw_sigma_deg", p.yaw_sigma * 180.0 / M_PI, 0.01, 180.0, "deg") * M_PI / 180.0;
  p.latency_median = map.NumberOr("latency_median", p.latency_median, 1e-3, 60.0, "s");
  p.latency_log_sigma = map.NumberOr("latency_log_sigma", p.latency_log_sigma, 0.0, 10.0);
  p.latency_max = map.NumberOr("latency_max", p.latency_max, 1e-3, 60.0, "s");
  p.outlier_probability = map.NumberOr("outlier_probability", p.outlier_probability, 0.0, 1.0);
  p.outlier_min = map.NumberOr("outlier_min", p.outlier_min, 0.0, 1000.0, "m");
  p.outlier_max = map.NumberOr("outlier_max", p.outlier_max, 0.0, 1000.0, "m");
  map.RejectUnknownKeys();
  if (p.latency_max < p.latency_median) map.Fail("latency_max", "must be at least latency_median");
  if (p.outlier_max < p.outlier_min) map.Fail("outlier_max", "must be at least outlier_min");
  return p;
}

Survey ReadSurvey(const YamlMap& map, std::uint64_t scenario_seed) {
  Survey survey;
  survey.point_sigma = map.NumberOr("point_sigma", survey.point_sigma, 0.0, 1.0, "m");
  survey.seed = ReadSeed(map, scenario_seed);
  survey.per_trial = map.Bool("per_trial", false);
  if (survey.per_trial && map.Has("seed")) {
    map.Fail("seed", "a survey drawn per trial takes each trial's seed; give the scenario's seed instead");
  }
  survey.growth = map.NumberOr("growth", 0.0, 0.0, 1.0);
  if (map.Has("unmapped")) {
    survey.unmapped = map.Integers("unmapped", 1, garden::kMaxGardenObjectId);
  }
  if (map.Has("gone")) {
    for (const YamlMap& item : map.MapList("gone")) survey.gone.push_back(garden::ReadGardenObject(item));
  }
  if (map.Has("unmapped_objects")) {
    for (const YamlMap& item : map.MapList("unmapped_objects")) {
      survey.unmapped_objects.push_back(garden::ReadGardenObject(item));
    }
  }
  map.RejectUnknownKeys();
  return survey;
}

CalibrationError ReadCalibrationError(const YamlMap& map) {
  CalibrationError e;
  e.focal_relative = map.NumberOr("focal_relative", e.focal_relative, 0.0, 0.5);
  e.principal_point_px = map.NumberOr("principal_point_px", e.principal_point_px, 0.0, 100.0, "px");
  e.rotation_deg = map.NumberOr("rotation_deg", e.rotation_deg, 0.0, 30.0, "deg");
  e.translation_m = map.NumberOr("translation_m", e.translation_m, 0.0, 0.5, "m");
  e.camera_imu_time_offset_s = map.NumberOr("camera_imu_time_offset_s", e.camera_imu_time_offset_s, 0.0, 1.0, "s");
  e.seed = ReadSeed(map, e.seed);
  map.RejectUnknownKeys();
  return e;
}

// `visual_map: PATH` (a built map file) or `visual_map: {mapping_drive: PLAN, ...}` (a map built on
// first use from that drive and cached: runners/map_cache.h). Paths are relative to the scenario.
void ReadVisualMap(const YamlMap& root, Scenario& s) {
  const auto relative_to_scenario = [&](const std::filesystem::path& path) {
    return (path.is_absolute() ? path : std::filesystem::path(s.source).parent_path() / path).string();
  };
  if (!root.node()["visual_map"].IsMap()) {
    s.visual_map = relative_to_scenario(root.String("visual_map"));
    return;
  }
  const YamlMap spec = root.Map("visual_map");
  MapRecipe recipe;
  recipe.plan_path = relative_to_scenario(spec.String("mapping_drive"));
  if (spec.Has("seed")) recipe.seed = static_cast<std::uint64_t>(spec.Integer("seed", 0, 2147483647));
  if (spec.Has("seconds")) recipe.seconds = spec.Number("seconds", 1e-3, 1e6, "s");
  if (spec.Has("builder")) {
    try {
      recipe.builder = visual_localization::KeyframePosesFromString(spec.String("builder"));
    } catch (const std::invalid_argument& e) {
      spec.Fail("builder", e.what());
    }
  }
  recipe.survey_position_sigma = spec.NumberOr("survey_position_sigma", recipe.survey_position_sigma, 0.0, 1.0, "m");
  recipe.survey_rotation_sigma_deg =
      spec.NumberOr("survey_rotation_sigma_deg", recipe.survey_rotation_sigma_deg, 0.0, 10.0, "deg");
  spec.RejectUnknownKeys();
  recipe.calibration_error = s.calibration_error;  // the map is built with the robot's calibration
  s.visual_map_recipe = recipe;
}

void ReadMission(const YamlMap& root, Scenario& s) {
  if (root.Has("map")) {
    const YamlMap map = root.Map("map");
    s.map_resolution = map.NumberOr("resolution", s.map_resolution, 0.005, 1.0, "m");
    if (map.Has("clearance_height")) s.map_clearance_height = map.Number("clearance_height", 0.0, 10.0, "m");
    map.RejectUnknownKeys();
  }
  s.survey.seed = s.setting.seed;
  if (root.Has("survey")) s.survey = ReadSurvey(root.Map("survey"), s.setting.seed);
  for (const YamlMap& goal :
       root.Has("goals") || !root.Has("arm_reach") ? root.MapList("goals") : std::vector<YamlMap>{}) {
    ScenarioGoal g;
    const int kinds = goal.Has("approach_bush") + goal.Has("trim_bush") + goal.Has("scan_bush");
    if (kinds > 1) goal.Fail("trim_bush", "a goal approaches, scans or trims a bush, one of them");
    if (kinds == 1) {
      g.trim = !goal.Has("approach_bush");
      g.cut = goal.Has("trim_bush");
      const char* key = g.cut ? "trim_bush" : g.trim ? "scan_bush" : "approach_bush";
      g.bush = goal.Integer(key, 1, garden::kMaxGardenObjectId);  // checked against the garden later
      if (goal.Has("yaw_deg")) goal.Fail("yaw_deg", "a bush goal's heading is the bush's bearing (give none)");
      if (goal.Has("side_deg")) g.side = goal.Number("side_deg", -360.0, 360.0, "deg") * M_PI / 180.0;
    } else {
      g.position = {goal.Number("x", -1e4, 1e4, "m"), goal.Number("y", -1e4, 1e4, "m")};
      if (goal.Has("yaw_deg")) g.yaw = goal.Number("yaw_deg", -360.0, 360.0, "deg") * M_PI / 180.0;
    }
    goal.RejectUnknownKeys();
    s.goals.push_back(g);
  }
  if (root.Has("arm_reach")) {
    const YamlMap spec = root.Map("arm_reach");
    ArmReach a;
    a.bush = spec.Integer("bush", 1, garden::kMaxGardenObjectId);  // checked against the garden later
    a.poses = spec.Integer("poses", 1, 10000);
    a.distance_min = spec.NumberOr("distance_min", a.distance_min, 0.0, 2.0, "m");
    a.distance_max = spec.NumberOr("distance_max", a.distance_max, 0.0, 2.0, "m");
    if (a.distance_max <= a.distance_min) spec.Fail("distance_max", "must exceed distance_min");
    a.max_tilt = spec.NumberOr("max_tilt_deg", a.max_tilt * 180.0 / M_PI, 0.0, 180.0, "deg") * M_PI / 180.0;
    a.min_clearance = spec.NumberOr("min_clearance", a.min_clearance, 0.0, 1.0, "m");
    a.position_tolerance = spec.NumberOr("position_tolerance", a.position_tolerance, 1e-5, 1.0, "m");
    a.orientation_tolerance =
        spec.NumberOr("orientation_tolerance_deg", a.orientation_tolerance * 180.0 / M_PI, 1e-3, 180.0, "deg") * M_PI /
        180.0;
    if (spec.Has("renders")) a.renders = spec.Integer("renders", 0, 1000);
    spec.RejectUnknownKeys();
    s.arm_reach = a;
    if (!s.goals.empty()) root.Fail("goals", "an arm_reach scenario has no navigation goals (the base stands)");
  } else if (s.goals.empty()) {
    root.Fail("goals", "needs at least one goal");
  }
  s.goal_tolerance = root.NumberOr("goal_tolerance", s.goal_tolerance, 1e-3, 10.0, "m");
  s.goal_yaw_tolerance =
      root.NumberOr("goal_yaw_tolerance_deg", s.goal_yaw_tolerance * 180.0 / M_PI, 0.1, 180.0, "deg") * M_PI / 180.0;
  if (root.Has("bush_tolerance")) {
    const YamlMap tolerance = root.Map("bush_tolerance");
    s.bush_distance_tolerance = tolerance.NumberOr("distance", s.bush_distance_tolerance, 1e-4, 10.0, "m");
    s.bush_bearing_tolerance =
        tolerance.NumberOr("bearing_deg", s.bush_bearing_tolerance * 180.0 / M_PI, 1e-3, 180.0, "deg") * M_PI / 180.0;
    tolerance.RejectUnknownKeys();
  }
  if (root.Has("initial_pose_sigma")) {
    const YamlMap sigma = root.Map("initial_pose_sigma");
    s.initial_position_sigma = sigma.NumberOr("position", s.initial_position_sigma, 0.0, 10.0, "m");
    s.initial_yaw_sigma =
        sigma.NumberOr("yaw_deg", s.initial_yaw_sigma * 180.0 / M_PI, 0.0, 180.0, "deg") * M_PI / 180.0;
    sigma.RejectUnknownKeys();
  }
  if (root.Has("calibration_error")) s.calibration_error = ReadCalibrationError(root.Map("calibration_error"));
  if (root.Has("visual_map")) ReadVisualMap(root, s);
  if (root.Has("cutting_path_database")) {
    const std::filesystem::path path = root.String("cutting_path_database");
    s.cutting_path_database =
        (path.is_absolute() ? path : std::filesystem::path(s.source).parent_path() / path).string();
    if (std::none_of(s.goals.begin(), s.goals.end(), [](const ScenarioGoal& g) { return g.cut; })) {
      root.Fail("cutting_path_database", "is for trim goals (trim_bush), and the scenario has none");
    }
  }
}

void ReadPlant(const YamlMap& root, Scenario& s) {
  if (root.Has("cameras")) {
    const YamlMap cameras = root.Map("cameras");
    s.render_cameras = cameras.Bool("render", s.render_cameras);
    s.resolution_scale = cameras.NumberOr("resolution_scale", s.resolution_scale, 0.05, 1.0);
    s.motion_blur = cameras.Bool("motion_blur", s.motion_blur);
    cameras.RejectUnknownKeys();
  }
  if (root.Has("noise")) {
    const YamlMap noise = root.Map("noise");
    s.imu_noise_scale = noise.NumberOr("imu", 1.0, 0.0, 100.0);
    s.wheel_slip_scale = noise.NumberOr("wheel_slip", 1.0, 0.0, 100.0);
    noise.RejectUnknownKeys();
  }
  if (root.Has("simulated_pose_fixes")) {
    s.simulated_pose_fixes = ReadSimulatedPoseFixes(root.Map("simulated_pose_fixes"));
    s.simulated_pose_fixes_given = true;
  }
  if (root.Has("faults")) {
    for (const YamlMap& item : root.MapList("faults")) s.faults.push_back(ReadFault(item));
  }
}

}  // namespace

std::vector<PassCriterion> ReadPassCriteria(const YamlMap& criteria) {
  std::vector<PassCriterion> read;
  for (const auto& entry : criteria.node()) {
    if (!entry.first.IsScalar()) criteria.Fail("criteria", "metric names must be plain names");
    const std::string metric = entry.first.as<std::string>();
    if (!IsKnownMetric(metric)) criteria.Fail(metric, "unknown metric");
    const YamlMap bound = criteria.Map(metric);
    PassCriterion criterion;
    criterion.metric = metric;
    if (bound.Has("min") == bound.Has("max")) bound.Fail("min", "give exactly one of min or max");
    criterion.comparison = bound.Has("min") ? ">=" : "<=";
    criterion.threshold = bound.Has("min") ? bound.Number("min", -1e12, 1e12) : bound.Number("max", -1e12, 1e12);
    bound.RejectUnknownKeys();
    read.push_back(criterion);
  }
  criteria.RejectUnknownKeys();
  return read;
}

namespace {

RobotReference ReadRobotReference(const YamlMap& map) {
  RobotReference reference;
  reference.source = map.String("source");
  if (map.Has("frame_seconds")) reference.frame_seconds = map.Number("frame_seconds", 1e-6, 1e3, "s");
  const YamlMap metrics = map.Map("metrics");
  for (const auto& entry : metrics.node()) {
    const std::string metric = entry.first.as<std::string>();
    if (!IsKnownMetric(metric)) metrics.Fail(metric, "unknown metric");
    reference.metrics.emplace_back(metric, metrics.Number(metric, 0.0, 1e12));  // every metric is >= 0
  }
  metrics.RejectUnknownKeys();
  if (reference.metrics.empty()) map.Fail("metrics", "needs at least one of the robot's figures");
  map.RejectUnknownKeys();
  return reference;
}

}  // namespace

bool IsKnownMetric(const std::string& name) {
  static const std::set<std::string> kMetrics = [] {
    std::set<std::string> names = {
        "success_rate", "goal_success_rate",  "trials_completed",   "goal_success_rate_as_asked", "collisions",
        "recoveries",   "mean_trial_seconds", "mean_path_length_m", "localization_rate",          "min_clearance_m"};
    names.insert({"visual_frame_success_rate", "visual_frame_rate_hz", "ekf_nees_mean", "ekf_nees_within_95_rate",
                  "pose_fixes_nees_mean", "pose_fixes_nees_within_95_rate"});
    names.insert({"bush_goals", "bush_frames_1_3m", "bush_frame_found_rate", "bush_frame_within_rate"});
    names.insert({"arm_goals", "arm_success_rate", "arm_contacts", "arm_tracking_error_max_rad", "arm_min_clearance_m",
                  "arm_position_error_mean_m", "arm_position_error_max_m", "arm_orientation_error_mean_deg",
                  "arm_orientation_error_max_deg", "arm_path_length_mean_rad", "arm_cutter_path_length_mean_m"});
    names.insert({"trim_goals", "trim_success_rate", "trim_arm_contacts", "trim_foliage_touches",
                  "trim_within_2cm_before_mean", "trim_within_2cm_after_mean", "trim_within_2cm_after_min",
                  "trim_within_2cm_upper_before_mean", "trim_within_2cm_upper_after_mean", "trim_overcut_mean",
                  "trim_overcut_max", "trim_fit_centre_error_max_m", "trim_cutting_seconds_mean"});
    for (const char* bush : {"bush_distance_error", "bush_bearing_error", "bush_estimate_distance_error",
                             "bush_estimate_bearing_error", "bush_frame_distance_error", "bush_frame_bearing_error"}) {
      names.insert(std::string(bush) + "_mean");
      names.insert(std::string(bush) + "_max");
    }
    for (const char* estimate : {"ekf", "wheel_odometry", "pose_fixes"}) {
      for (const char* stat : {"mean", "median", "max", "rmse"}) {
        names.insert(std::string(estimate) + "_position_error_" + stat + "_m");
        if (std::string(stat) != "rmse") names.insert(std::string(estimate) + "_heading_error_" + stat + "_deg");
      }
    }
    return names;
  }();
  return kMetrics.count(name) > 0;
}

Scenario Scenario::Load(const std::string& path, const std::vector<Override>& overrides) {
  const YamlMap file = YamlMap::LoadFile(path);
  Scenario s;
  s.source = path;
  std::ifstream text(path);
  s.effective_yaml.assign(std::istreambuf_iterator<char>(text), std::istreambuf_iterator<char>());
  YAML::Node tree = file.node();
  if (!overrides.empty()) {
    tree = YAML::Clone(file.node());
    ApplyOverrides(tree, overrides, path);
    YAML::Emitter emitter;
    emitter << tree;
    s.effective_yaml = "# " + path + " with";
    for (const auto& o : overrides) {
      s.effective_yaml += " --set " + o.text;
      s.overrides.push_back(o.text);
    }
    s.effective_yaml += "\n" + std::string(emitter.c_str()) + "\n";
  }
  const YamlMap root(tree, overrides.empty() ? path : path + " (with --set)", "");
  s.name = root.String("name");
  s.description = root.String("description", "");
  s.setting = Setting::Read(root, /*with_seed=*/true);
  ReadMission(root, s);
  s.trials = root.Has("trials") ? root.Integer("trials", 1, 100000) : 1;
  s.time_limit = root.NumberOr("time_limit", s.time_limit, 1e-3, 1e6, "s");
  s.wall_time_limit = root.NumberOr("wall_time_limit", s.wall_time_limit, 1e-3, 1e7, "s");
  ReadPlant(root, s);
  if (root.Has("stack")) s.stack = root.Map("stack");
  if (root.Has("criteria")) s.criteria = ReadPassCriteria(root.Map("criteria"));
  if (root.Has("robot_reference")) s.robot_reference = ReadRobotReference(root.Map("robot_reference"));
  root.RejectUnknownKeys();
  return s;
}

}  // namespace trimbot::scenarios
