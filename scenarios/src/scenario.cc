#include "scenario.h"

#include <cmath>
#include <set>

#include "trimbot/common/yaml_reader.h"

namespace trimbot::scenarios {
namespace {

Eigen::Vector3d OptionalVector3(const YamlMap& map, const std::string& key) {
  return map.Has(key) ? map.Vector3(key) : Eigen::Vector3d::Zero();
}

sim::Fault ReadFault(const YamlMap& item) {
  sim::Fault fault;
  const std::string type = item.String("type");
  if (type == "wheel_slip") {
    fault.kind = sim::Fault::Kind::kWheelSlip;
    fault.start = item.Double("start");
    fault.duration = item.Double("duration");
    fault.slip_left = item.Double("left", 0.0);
    fault.slip_right = item.Double("right", 0.0);
    if (fault.slip_left <= -1.0) item.Fail("left", "slip must be greater than -1");
    if (fault.slip_right <= -1.0) item.Fail("right", "slip must be greater than -1");
  } else if (type == "imu_bias_jump") {
    fault.kind = sim::Fault::Kind::kImuBiasJump;
    fault.start = item.Double("time");
    fault.gyroscope_bias_jump = OptionalVector3(item, "gyro");
    fault.accelerometer_bias_jump = OptionalVector3(item, "accel");
  } else if (type == "camera_dropout") {
    fault.kind = sim::Fault::Kind::kCameraDropout;
    fault.start = item.Double("start");
    fault.duration = item.Double("duration");
  } else {
    item.Fail("type", "unknown fault '" + type + "' (wheel_slip, imu_bias_jump, camera_dropout)");
  }
  if (fault.start < 0.0) item.Fail(type == "imu_bias_jump" ? "time" : "start", "must not be negative");
  if (fault.kind != sim::Fault::Kind::kImuBiasJump && !(fault.duration > 0.0)) item.Fail("duration", "must be positive");
  item.RejectUnknownKeys();
  return fault;
}

sim::PoseFixModelParameters ReadPoseFixes(const YamlMap& map) {
  sim::PoseFixModelParameters p;
  p.enabled = map.Bool("enabled", true);
  p.availability = map.Double("availability", p.availability);
  p.position_sigma = map.Double("position_sigma", p.position_sigma);
  p.yaw_sigma = map.Double("yaw_sigma_deg", p.yaw_sigma * 180.0 / M_PI) * M_PI / 180.0;
  p.latency_median = map.Double("latency_median", p.latency_median);
  p.latency_log_sigma = map.Double("latency_log_sigma", p.latency_log_sigma);
  p.latency_max = map.Double("latency_max", p.latency_max);
  p.outlier_probability = map.Double("outlier_probability", p.outlier_probability);
  p.outlier_min = map.Double("outlier_min", p.outlier_min);
  p.outlier_max = map.Double("outlier_max", p.outlier_max);
  map.RejectUnknownKeys();
  for (const auto& [key, value] : {std::pair{"availability", p.availability}, {"outlier_probability", p.outlier_probability}}) {
    if (value < 0.0 || value > 1.0) map.Fail(key, "must be between 0 and 1");
  }
  if (p.position_sigma < 0.0) map.Fail("position_sigma", "must not be negative");
  if (!(p.latency_median > 0.0)) map.Fail("latency_median", "must be positive");
  if (p.latency_max < p.latency_median) map.Fail("latency_max", "must be at least latency_median");
  return p;
}

}  // namespace

bool IsKnownMetric(const std::string& name) {
  static const std::set<std::string> kMetrics = [] {
    std::set<std::string> names = {"success_rate",      "goal_success_rate", "trials_completed",
                                   "collisions",        "recoveries",        "mean_trial_seconds",
                                   "mean_wall_seconds", "mean_path_length_m"};
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

Scenario Scenario::Load(const std::string& path) {
  const YamlMap root = YamlMap::LoadFile(path);
  Scenario s;
  s.source = path;
  s.name = root.String("name");
  s.description = root.String("description", "");
  s.garden = root.String("garden");
  if (root.Has("map")) {
    const YamlMap map = root.Map("map");
    s.map_resolution = map.Double("resolution", s.map_resolution);
    s.map_clearance_height = map.Double("clearance_height", s.map_clearance_height);
    map.RejectUnknownKeys();
    if (!(s.map_resolution > 0.0)) map.Fail("resolution", "must be positive");
  }
  const auto finite = [](const YamlMap& map, const std::string& key, double value) {
    if (!std::isfinite(value)) map.Fail(key, "must be a finite number");
    return value;
  };
  const YamlMap start = root.Map("start");
  s.start.x = finite(start, "x", start.Double("x"));
  s.start.y = finite(start, "y", start.Double("y"));
  s.start.yaw = finite(start, "yaw_deg", start.Double("yaw_deg", 0.0)) * M_PI / 180.0;
  start.RejectUnknownKeys();
  for (const YamlMap& goal : root.MapList("goals")) {
    s.goals.emplace_back(finite(goal, "x", goal.Double("x")), finite(goal, "y", goal.Double("y")));
    goal.RejectUnknownKeys();
  }
  if (s.goals.empty()) root.Fail("goals", "needs at least one goal");
  s.speed = root.Double("speed", s.speed);
  if (!(s.speed > 0.0 && s.speed <= 0.6)) root.Fail("speed", "must be in (0, 0.6] m/s (the base's limit)");
  s.goal_tolerance = root.Double("goal_tolerance", s.goal_tolerance);
  if (!(s.goal_tolerance > 0.0)) root.Fail("goal_tolerance", "must be positive");
  if (root.Has("conditions")) s.conditions = garden::Conditions::FromYaml(root.Map("conditions"));
  const int seed = root.Int("seed", 1);
  if (seed < 0) root.Fail("seed", "must not be negative");
  s.seed = static_cast<std::uint64_t>(seed);
  s.trials = root.Int("trials", 1);
  if (s.trials < 1) root.Fail("trials", "must be at least 1");
  s.time_limit = root.Double("time_limit", s.time_limit);
  if (!(s.time_limit > 0.0)) root.Fail("time_limit", "must be positive");
  s.wall_time_limit = root.Double("wall_time_limit", s.wall_time_limit);
  if (!(s.wall_time_limit > 0.0)) root.Fail("wall_time_limit", "must be positive");
  if (root.Has("cameras")) {
    const YamlMap cameras = root.Map("cameras");
    s.render_cameras = cameras.Bool("render", s.render_cameras);
    s.resolution_scale = cameras.Double("resolution_scale", s.resolution_scale);
    cameras.RejectUnknownKeys();
    if (!(s.resolution_scale > 0.0 && s.resolution_scale <= 1.0)) cameras.Fail("resolution_scale", "must be in (0, 1]");
  }
  if (root.Has("noise")) {
    const YamlMap noise = root.Map("noise");
    s.imu_noise_scale = noise.Double("imu", 1.0);
    s.wheel_slip_scale = noise.Double("wheel_slip", 1.0);
    noise.RejectUnknownKeys();
    if (s.imu_noise_scale < 0.0) noise.Fail("imu", "must not be negative");
    if (s.wheel_slip_scale < 0.0) noise.Fail("wheel_slip", "must not be negative");
  }
  if (root.Has("localization")) {
    const YamlMap localization = root.Map("localization");
    if (localization.Has("pose_fixes")) s.pose_fixes = ReadPoseFixes(localization.Map("pose_fixes"));
    localization.RejectUnknownKeys();
  }
  if (root.Has("faults")) {
    for (const YamlMap& item : root.MapList("faults")) s.faults.push_back(ReadFault(item));
  }
  if (root.Has("criteria")) {
    const YamlMap criteria = root.Map("criteria");
    for (const auto& entry : criteria.node()) {
      if (!entry.first.IsScalar()) criteria.Fail("criteria", "metric names must be plain names");
      const std::string metric = entry.first.as<std::string>();
      if (!IsKnownMetric(metric)) criteria.Fail(metric, "unknown metric");
      const YamlMap bound = criteria.Map(metric);
      PassCriterion criterion;
      criterion.metric = metric;
      if (bound.Has("min") == bound.Has("max")) bound.Fail("min", "give exactly one of min or max");
      criterion.comparison = bound.Has("min") ? ">=" : "<=";
      criterion.threshold = bound.Has("min") ? bound.Double("min") : bound.Double("max");
      bound.RejectUnknownKeys();
      s.criteria.push_back(criterion);
    }
    criteria.RejectUnknownKeys();
  }
  root.RejectUnknownKeys();
  return s;
}

}  // namespace trimbot::scenarios
