#include "trimbot/stack/stack_parameters.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace trimbot::stack {
namespace {

constexpr double kDegree = M_PI / 180.0;

// Reads keys into fields that already hold their defaults. In a complete file every key must be
// there; in an override only the keys present are read. Either way unknown keys are errors.
class Reader {
 public:
  Reader(YamlMap map, bool complete) : map_(std::move(map)), complete_(complete) {}

  void Number(const char* key, double* value, double lo, double hi, const char* unit = "") {
    if (Wanted(key)) *value = map_.Number(key, lo, hi, unit);
  }
  void Degrees(const char* key, double* radians, double lo_deg, double hi_deg) {
    double degrees = *radians / kDegree;
    Number(key, &degrees, lo_deg, hi_deg, "deg");
    *radians = degrees * kDegree;
  }
  void Integer(const char* key, int* value, int lo, int hi) {
    if (Wanted(key)) *value = map_.Integer(key, lo, hi);
  }
  void Flag(const char* key, bool* value) {
    if (Wanted(key)) *value = map_.Bool(key);
  }
  template <typename Body>
  void Section(const char* key, Body body) {
    if (!Wanted(key)) return;
    Reader section(map_.Map(key), complete_);
    body(section);
    section.map_.RejectUnknownKeys();
  }
  const YamlMap& map() const { return map_; }
  bool Wanted(const char* key) const { return complete_ || map_.Has(key); }

 private:
  YamlMap map_;
  bool complete_;
};

void ReadEkf(Reader& r, EkfParameters& p) {
  r.Number("linear_acceleration_density", &p.linear_acceleration_density, 0.0, 100.0, "m/s^2/sqrt(Hz)");
  r.Number("angular_acceleration_density", &p.angular_acceleration_density, 0.0, 100.0, "rad/s^2/sqrt(Hz)");
  r.Number("gyro_bias_random_walk", &p.gyro_bias_random_walk, 0.0, 1.0, "rad/s^2/sqrt(Hz)");
  r.Number("wheel_speed_sigma", &p.wheel_speed_sigma, 1e-6, 10.0, "m/s");
  r.Number("wheel_slip_fraction", &p.wheel_slip_fraction, 0.0, 1.0);
  r.Number("wheel_scale_sigma", &p.wheel_scale_sigma, 1e-6, 1.0);
  r.Number("wheel_scale_random_walk", &p.wheel_scale_random_walk, 0.0, 1.0, "1/sqrt(s)");
  r.Number("gyro_sigma", &p.gyro_sigma, 1e-6, 10.0, "rad/s");
  r.Number("fix_gate_chi2", &p.fix_gate_chi2, 0.0, 1e6);  // 1e6: every fix passes
  r.Integer("relocalize_after_rejections", &p.relocalize_after_rejections, 1, 1000);
  r.Number("relocalize_consistency", &p.relocalize_consistency, 0.0, 100.0, "m");
  r.Number("history_seconds", &p.history_seconds, 0.1, 60.0, "s");
  r.Number("max_fix_lead", &p.max_fix_lead, 0.0, 10.0, "s");
}

void ReadVisual(Reader& r, VisualLocalizationParameters& p) {
  r.Number("rate_hz", &p.rate_hz, 0.01, 100.0, "Hz");
  if (r.Wanted("latency")) {
    const std::string mode = r.map().String("latency");
    if (mode != "deterministic" && mode != "measured") r.map().Fail("latency", "must be deterministic or measured");
    p.measured_latency = mode == "measured";
  }
  r.Number("latency_median", &p.latency_median, 1e-3, 60.0, "s");
  r.Number("latency_log_sigma", &p.latency_log_sigma, 0.0, 10.0);
  r.Number("latency_max", &p.latency_max, 1e-3, 60.0, "s");
  r.Integer("features", &p.features, 50, 100000);
  if (r.Wanted("descriptor")) {
    try {
      p.descriptor = visual_localization::DescriptorFromString(r.map().String("descriptor"));
    } catch (const std::invalid_argument& e) {
      r.map().Fail("descriptor", e.what());
    }
  }
  if (r.Wanted("cameras")) {
    const std::string cameras = r.map().String("cameras");
    if (cameras != "all" && cameras != "left") r.map().Fail("cameras", "must be all or left");
    p.left_cameras_only = cameras == "left";
  }
  r.Number("image_scale", &p.image_scale, 0.05, 1.0);
  r.Integer("keyframes", &p.keyframes, 1, 1000);
  r.Number("prior_radius", &p.prior_radius, 0.1, 1000.0, "m");
  r.Integer("min_inliers", &p.min_inliers, 4, 100000);
  r.Number("min_inlier_ratio", &p.min_inlier_ratio, 0.0, 1.0);
  r.Number("max_position_sigma", &p.max_position_sigma, 0.01, 1000.0, "m");
  if (p.latency_max < p.latency_median) r.map().Fail("latency_max", "must be at least latency_median");
}

void ReadPlanner(Reader& r, PlannerParameters& p) {
  r.Number("min_clearance", &p.min_clearance, 0.0, 2.0, "m");
  r.Number("preferred_clearance", &p.preferred_clearance, 0.0, 5.0, "m");
  r.Number("clearance_cost", &p.clearance_cost, 0.0, 100.0, "m per m");
  r.Number("start_free_radius", &p.start_free_radius, 0.0, 5.0, "m");
  r.Integer("iterations", &p.iterations, 10, 10000000);
  r.Number("range", &p.range, 0.05, 100.0, "m");
  r.Number("start_escape_radius", &p.start_escape_radius, 0.0, 10.0, "m");
}

void ReadFollower(Reader& r, FollowerParameters& p) {
  r.Number("cruise_speed", &p.cruise_speed, 0.01, 0.6, "m/s (the base's limit is 0.6)");
  r.Number("lookahead", &p.lookahead, 0.05, 10.0, "m");
  r.Number("max_angular_speed", &p.max_angular_speed, 0.01, 1.5, "rad/s");
  r.Number("align_tolerance", &p.align_tolerance, 0.001, M_PI, "rad");
  r.Number("turn_in_place_above", &p.turn_in_place_above, 0.0, M_PI, "rad");
  r.Number("heading_gain", &p.heading_gain, 0.01, 100.0, "1/s");
  r.Number("sharp_turn", &p.sharp_turn, 0.0, M_PI, "rad");
  r.Number("vertex_tolerance", &p.vertex_tolerance, 0.001, 1.0, "m");
  r.Number("goal_tolerance", &p.goal_tolerance, 0.001, 2.0, "m");
  r.Number("slow_down_distance", &p.slow_down_distance, 0.0, 10.0, "m");
  r.Number("min_speed", &p.min_speed, 0.001, 0.6, "m/s");
  r.Number("exact_below", &p.exact_below, 0.0, 10.0, "m");
  r.Number("exact_align_tolerance", &p.exact_align_tolerance, 0.001, M_PI, "rad");
  r.Number("exact_vertex_tolerance", &p.exact_vertex_tolerance, 0.001, 1.0, "m");
}

void ReadNavigation(Reader& r, StackParameters& s) {
  NavigatorParameters& p = s.navigation;
  r.Number("control_rate_hz", &s.control_rate_hz, 1.0, 400.0, "Hz");
  r.Section("planner", [&](Reader& f) { ReadPlanner(f, p.planner); });
  r.Section("follower", [&](Reader& f) { ReadFollower(f, p.follower); });
  r.Number("stop_clearance", &p.stop_clearance, -1.0, 2.0, "m");
  r.Number("turn_check_angle", &p.turn_check_angle, 0.0, M_PI, "rad");
  r.Number("resume_clearance", &p.resume_clearance, 0.0, 5.0, "m");
  r.Number("backoff_speed", &p.backoff_speed, 0.01, 0.6, "m/s");
  r.Number("max_backoff", &p.max_backoff, 0.0, 10.0, "m");
  r.Number("replan_deviation", &p.replan_deviation, 0.01, 100.0, "m");
  r.Integer("max_recoveries_per_goal", &p.max_recoveries_per_goal, 0, 1000);
  r.Integer("max_plan_failures", &p.max_plan_failures, 1, 1000);
  r.Flag("stop_on_failure", &p.stop_on_failure);
  r.Number("goal_search_radius", &p.goal_search_radius, 0.0, 2.0, "m");
  r.Number("blocked_horizon", &p.blocked_horizon, 0.0, 100.0, "m");
  if (p.resume_clearance < p.stop_clearance) r.map().Fail("resume_clearance", "must be at least stop_clearance");
  if (p.stop_clearance >= p.planner.min_clearance) {
    r.map().Fail("stop_clearance", "must be less than planner.min_clearance (the robot would stop on its own paths)");
  }
  if (p.follower.min_speed > p.follower.cruise_speed) {
    r.map().Fail("follower", "min_speed must not exceed cruise_speed");
  }
}

void ReadObstacles(Reader& r, ObstacleDetectionParameters& p) {
  r.Flag("enabled", &p.enabled);
  r.Number("rate_hz", &p.rate_hz, 0.01, 100.0, "Hz");
  r.Degrees("max_bearing_deg", &p.max_bearing, 0.0, 180.0);
  r.Integer("stride", &p.stride, 1, 64);
  perception::ObstaclePointOptions& points = p.points;
  r.Number("min_height", &points.min_height, 0.0, 5.0, "m");
  r.Number("max_height", &points.max_height, 0.0, 10.0, "m");
  r.Number("ground_tolerance", &points.ground_tolerance, 0.0, 1.0, "m");
  r.Number("max_position_sigma", &points.max_position_sigma, 1e-4, 10.0, "m");
  r.Section("layer", [&](Reader& f) {
    ObstacleLayerParameters& l = p.layer;
    f.Number("size", &l.size, 1.0, 200.0, "m");
    f.Number("hit", &l.hit, 1e-3, 10.0);
    f.Number("miss", &l.miss, -10.0, -1e-3);
    f.Number("occupied", &l.occupied, 0.0, 10.0);
    f.Number("limit", &l.limit, 0.0, 100.0);
    f.Number("decay_time", &l.decay_time, 0.1, 1e6, "s");
    f.Integer("min_points", &l.min_points, 1, 65535);
    if (l.limit <= l.occupied) f.map().Fail("limit", "must exceed occupied");
  });
  if (points.max_height <= points.min_height) r.map().Fail("max_height", "must exceed min_height");
  if (points.ground_tolerance > points.min_height) r.map().Fail("ground_tolerance", "must not exceed min_height");
}

void ReadBushApproach(Reader& r, BushApproachParameters& p) {
  r.Number("rate_hz", &p.rate_hz, 0.01, 100.0, "Hz");
  r.Number("sighting_range", &p.sighting_range, 0.5, 20.0, "m");
  r.Number("approach_margin", &p.approach_margin, 0.0, 5.0, "m");
  r.Degrees("max_bearing_deg", &p.max_bearing, 1.0, 90.0);
  r.Section("fit", [&](Reader& f) {
    perception::BushFitOptions& o = p.fit;
    f.Number("gate", &o.gate, 0.0, 2.0, "m");
    f.Number("refit_gate", &o.refit_gate, 0.005, 1.0, "m");
    f.Number("min_height", &o.min_height, 0.0, 1.0, "m");
    f.Number("max_position_sigma", &o.max_position_sigma, 1e-4, 10.0, "m");
    f.Integer("min_points", &o.min_points, 3, 1000000);
    f.Integer("max_points", &o.max_points, 3, 1000000);
    f.Number("huber", &o.huber, 1e-4, 1.0, "m");
    f.Number("scale_sigma", &o.scale_sigma, 1e-3, 10.0);
    if (o.max_points < o.min_points) f.map().Fail("max_points", "must be at least min_points");
  });
  r.Section("servo", [&](Reader& f) {
    BushServoParameters& o = p.servo;
    f.Number("surface_gap", &o.surface_gap, 0.0, 3.0, "m");
    f.Degrees("bearing_deg", &o.bearing, -180.0, 180.0);
    f.Number("distance_tolerance", &o.distance_tolerance, 1e-4, 1.0, "m");
    f.Degrees("bearing_tolerance_deg", &o.bearing_tolerance, 0.01, 45.0);
    f.Degrees("turn_first_deg", &o.turn_first, 0.01, 180.0);
    f.Number("gain", &o.gain, 0.001, 100.0, "1/s");
    f.Number("turn_gain", &o.turn_gain, 0.001, 100.0, "1/s");
    f.Number("max_speed", &o.max_speed, 0.001, 1.0, "m/s");
    f.Number("min_speed", &o.min_speed, 0.0, 1.0, "m/s");
    f.Number("max_turn_rate", &o.max_turn_rate, 0.001, 3.0, "rad/s");
    f.Number("min_turn_rate", &o.min_turn_rate, 0.0, 3.0, "rad/s");
    f.Number("range_sigma", &o.range_sigma, 1e-5, 1.0, "m");
    f.Number("max_jump", &o.max_jump, 0.001, 2.0, "m");
    f.Number("first_gate_margin", &o.first_gate_margin, 0.0, 5.0, "m");
    f.Number("memory", &o.memory, 0.0, 1.0);
    f.Integer("settle_frames", &o.settle_frames, 0, 100);
    f.Number("settle_time", &o.settle_time, 0.0, 10.0, "s");
    f.Integer("max_lost_frames", &o.max_lost_frames, 0, 1000);
    f.Number("timeout", &o.timeout, 1.0, 1e5, "s");
  });
}

void ReadArm(Reader& r, arm::ArmExecutiveParameters& p) {
  r.Section("planner", [&](Reader& f) {
    arm::ArmPlannerParameters& o = p.planner;
    if (f.Wanted("algorithm")) {
      const std::string name = f.map().String("algorithm");
      if (name == "rrt_connect") {
        o.algorithm = arm::ArmPlannerParameters::Algorithm::kRrtConnect;
      } else if (name == "lazy_prm") {
        o.algorithm = arm::ArmPlannerParameters::Algorithm::kLazyPrm;
      } else {
        f.map().Fail("algorithm", "unknown planner '" + name + "' (rrt_connect, lazy_prm)");
      }
    }
    f.Integer("max_iterations", &o.max_iterations, 1, 10000000);
    f.Number("collision_step", &o.collision_step, 1e-4, 0.5, "rad");
    f.Number("velocity_scale", &o.velocity_scale, 0.01, 1.0);
    f.Number("acceleration", &o.acceleration, 0.01, 100.0, "rad/s^2");
    f.Number("cartesian_step", &o.cartesian_step, 1e-4, 0.1, "m");
    f.Number("cartesian_max_joint_step", &o.cartesian_max_joint_step, 1e-3, 1.0, "rad");
    f.Number("body_clearance", &o.body_clearance, 0.0, 0.1, "m");
    f.Integer("ik_database_seeds", &o.ik.database_seeds, 0, 100000);
    f.Integer("ik_starts", &o.ik.starts, 0, 10000);
    if (o.ik.database_seeds + o.ik.starts == 0) f.map().Fail("ik_starts", "inverse kinematics needs seeds or starts");
  });
  r.Section("environment", [&](Reader& f) {
    f.Number("cell", &p.cell, 0.005, 0.5, "m");
    f.Number("margin", &p.margin, 0.0, 0.5, "m");
    f.Integer("min_points_per_cell", &p.min_points_per_cell, 1, 100000);
    f.Number("max_point_sigma", &p.max_point_sigma, 1e-4, 10.0, "m");
    f.Number("reach", &p.reach, 0.1, 10.0, "m");
    f.Number("ground_clearance", &p.ground_clearance, 0.0, 1.0, "m");
    f.Number("body_margin", &p.body_margin, 0.0, 1.0, "m");
  });
  r.Section("execution", [&](Reader& f) {
    f.Number("settle_tolerance", &p.settle_tolerance, 1e-5, 1.0, "rad");
    f.Number("settle_timeout", &p.settle_timeout, 0.01, 1000.0, "s");
  });
}

void ReadTrim(Reader& r, trimming::TrimParameters& p) {
  r.Number("surface_gap", &p.surface_gap, 0.0, 3.0, "m");
  r.Number("scan_margin", &p.scan_margin, 0.0, 2.0, "m");
  r.Number("min_height", &p.min_height, 0.0, 1.0, "m");
  r.Number("max_point_sigma", &p.max_point_sigma, 1e-4, 10.0, "m");
  r.Integer("max_points", &p.max_points, 10, 10000000);
  r.Number("scan_overlap", &p.scan_overlap, 0.0, 1.0, "m");
  r.Number("fit_quantile", &p.fit.quantile, 0.01, 0.99);
  r.Number("pose_spacing", &p.poses.spacing, 0.01, 1.0, "m");
  r.Degrees("max_facing_angle_deg", &p.poses.max_facing_angle, 1.0, 180.0);
  r.Number("min_blade_height", &p.poses.min_height, 0.0, 2.0, "m");
  r.Integer("rolls", &p.path.rolls, 1, 360);
  r.Integer("search_restarts", &p.path.search.restarts, 1, 1000);
  r.Integer("search_warm_restarts", &p.path.search.warm_restarts, 0, 1000);
  r.Number("blade_depth", &p.blade_depth, 0.0, 0.2, "m");
  r.Number("leaf_quantile", &p.leaf_quantile, 0.5, 1.0);
  r.Number("leaf_clearance", &p.leaf_clearance, 0.0, 0.5, "m");
  r.Number("database_max_distance", &p.database_max_distance, 0.0, 10.0, "m");
}

void ReadLocalization(const YamlMap& map, LocalizationSource* source) {
  const std::string name = map.String("localization");
  if (name == "none") {
    *source = LocalizationSource::kNone;
  } else if (name == "simulated_pose_fixes") {
    *source = LocalizationSource::kSimulatedPoseFixes;
  } else if (name == "visual") {
    *source = LocalizationSource::kVisual;
  } else {
    map.Fail("localization", "unknown source '" + name + "' (none, visual, simulated_pose_fixes)");
  }
}

void Read(Reader& r, StackParameters& s) {
  if (r.Wanted("localization")) ReadLocalization(r.map(), &s.localization);
  r.Section("initial_pose_sigma", [&](Reader& f) {
    f.Number("position", &s.initial_position_sigma, 1e-4, 100.0, "m");
    f.Degrees("yaw_deg", &s.initial_yaw_sigma, 0.01, 180.0);
  });
  r.Section("ekf", [&](Reader& f) { ReadEkf(f, s.ekf); });
  r.Section("visual_localization", [&](Reader& f) { ReadVisual(f, s.visual); });
  r.Section("navigation", [&](Reader& f) { ReadNavigation(f, s); });
  r.Section("bush_approach", [&](Reader& f) { ReadBushApproach(f, s.bush_approach); });
  r.Section("arm", [&](Reader& f) { ReadArm(f, s.arm); });
  r.Section("trim", [&](Reader& f) { ReadTrim(f, s.trim); });
  r.Section("perception", [&](Reader& perception) {
    perception.Section("local_fusion", [&](Reader& f) {
      perception::LocalFusionOptions& p = s.local_fusion;
      f.Flag("enabled", &p.enabled);
      f.Number("interval", &p.interval, 0.05, 3600.0, "s");
      f.Integer("stride", &p.stride, 1, 64);
      f.Number("ground_keep", &p.ground_keep, 0.0, 1.0);
    });
    perception.Section("obstacles", [&](Reader& f) { ReadObstacles(f, s.obstacles); });
  });
}

}  // namespace

trimming::TrimParameters StackParameters::Trim() const {
  trimming::TrimParameters p = trim;
  p.planner = arm.planner;
  p.settle_tolerance = arm.settle_tolerance;
  p.settle_timeout = arm.settle_timeout;
  return p;
}

const char* ToString(LocalizationSource source) {
  switch (source) {
    case LocalizationSource::kNone:
      return "none";
    case LocalizationSource::kSimulatedPoseFixes:
      return "simulated_pose_fixes";
    case LocalizationSource::kVisual:
      return "visual";
  }
  return "?";
}

StackParameters StackParameters::Load(const std::string& path) {
  const YamlMap root = YamlMap::LoadFile(path);
  StackParameters parameters;
  Reader reader(root, /*complete=*/true);
  Read(reader, parameters);
  reader.map().RejectUnknownKeys();
  return parameters;
}

StackParameters StackParameters::Overridden(const YamlMap& section) const {
  StackParameters parameters = *this;
  Reader reader(section, /*complete=*/false);
  Read(reader, parameters);
  reader.map().RejectUnknownKeys();
  return parameters;
}

}  // namespace trimbot::stack
