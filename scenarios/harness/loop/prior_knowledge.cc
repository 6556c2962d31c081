#include "loop/prior_knowledge.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/pose2.h"
#include "trimbot/common/random.h"
#include "trimbot/common/rotation.h"
#include "trimbot/garden/conditions.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/robot/robot_parameters.h"

namespace trimbot::scenarios {
namespace {

// What a tape survey records of `object` (Survey::point_sigma): its centre off by one point's
// error, each extent by two, an elongated object's yaw by its two ends' over its length. Each
// object draws from its own stream (by id), so removing one object leaves the others' errors.
void AddSurveyError(const Survey& survey, garden::GardenObject& object) {
  Rng rng = MakeRng(survey.seed, "survey/object/" + std::to_string(object.id));
  const double sigma = survey.point_sigma;
  const Eigen::Vector2d centre_error(StandardNormal(rng), StandardNormal(rng));
  const Eigen::Vector3d extent_error(StandardNormal(rng), StandardNormal(rng), StandardNormal(rng));
  const double yaw_error = StandardNormal(rng);
  const double length = object.size.head<2>().maxCoeff();
  // A round object (cylinder or ellipsoid with equal extents) has no yaw to measure.
  const bool elongated = object.shape == garden::Shape::kBox || object.size.x() != object.size.y();
  object.position += sigma * centre_error;
  // A tape cannot read less than half the true extent (a 3-sigma error on a 5 cm post would).
  object.size = (object.size + std::sqrt(2.0) * sigma * extent_error).cwiseMax(0.5 * object.size);
  if (elongated) object.yaw += std::sqrt(2.0) * sigma / length * yaw_error;
}

}  // namespace

garden::Garden SurveyedGarden(const garden::Garden& built, const Survey& survey, const std::string& scenario_file) {
  garden::Garden surveyed = built;
  try {
    garden::Garden in_trials = built;  // checked here, before any trial: placed by the simulator
    in_trials.AddObjects(survey.unmapped_objects);
  } catch (const std::invalid_argument& e) {
    throw InputError(scenario_file, std::string("survey.unmapped_objects: ") + e.what());
  }
  for (int id : survey.unmapped) {
    const auto it = std::find_if(surveyed.objects.begin(), surveyed.objects.end(),
                                 [id](const garden::GardenObject& o) { return o.id == id; });
    if (it == surveyed.objects.end()) {
      throw InputError(scenario_file,
                       "survey.unmapped: garden '" + built.name + "' has no object " + std::to_string(id));
    }
    surveyed.objects.erase(it);
  }
  // Foliage grown at survey time: its outline pushed out by the growth on every side.
  for (auto& object : surveyed.objects) {
    if (garden::IsFoliage(object.object_class)) {
      object.size.head<2>() += Eigen::Vector2d::Constant(2.0 * survey.growth * garden::kMaxGrowth);
    }
    if (survey.point_sigma > 0.0) AddSurveyError(survey, object);
  }
  surveyed.objects.insert(surveyed.objects.end(), survey.gone.begin(), survey.gone.end());
  return surveyed;
}

double MapClearanceHeight(const Scenario& scenario, const ProjectPaths& paths) {
  return scenario.map_clearance_height ? *scenario.map_clearance_height : RobotClearanceHeight(paths);
}

double RobotClearanceHeight(const ProjectPaths& paths) {
  const robot::RobotFiles files = paths.robot_files();
  const robot::RobotDescription description = robot::RobotDescription::Load(files.urdf);
  const robot::RobotParameters parameters = robot::RobotParameters::Load(files.robot_parameters);
  std::map<std::string, double> home;
  for (int i = 0; i < static_cast<int>(parameters.arm_home_position.size()); ++i) {
    home[robot::RobotFrames::ArmJoint(i)] = parameters.arm_home_position[static_cast<std::size_t>(i)];
  }
  constexpr double kMargin = 0.05;  // m between the robot's top and a crown it passes under
  return description.Top(home) + kMargin;
}

garden::OccupancyMap PriorMap(const Scenario& scenario, const garden::Garden& surveyed, double clearance_height) {
  return garden::MakeOccupancyMap(surveyed, scenario.map_resolution, clearance_height);
}

std::string WritePriorMap(const garden::OccupancyMap& map, const std::string& dir) {
  garden::WriteOccupancyMap(map, dir, "map");
  return dir + "/map.yaml";
}

const garden::GardenObject& BushOf(const garden::Garden& garden, int id, const Scenario& scenario,
                                   const std::string& what) {
  const auto it = std::find_if(garden.objects.begin(), garden.objects.end(),
                               [id](const garden::GardenObject& o) { return o.id == id; });
  if (it == garden.objects.end()) {
    throw InputError(scenario.source, what + ": the garden '" + garden.name + "' has no object " + std::to_string(id));
  }
  if (it->object_class != garden::ObjectClass::kTopiary && it->object_class != garden::ObjectClass::kRose) {
    throw InputError(scenario.source, what + ": object " + std::to_string(id) + " is a " +
                                          garden::ToString(it->object_class) + ", not a bush (topiary or rose)");
  }
  return *it;
}

namespace {

std::string ApproachBush(int id) { return "goals: approach_bush " + std::to_string(id); }

perception::BushShape ShapeOf(const garden::GardenObject& object) {
  perception::BushShape shape;
  shape.kind = object.shape == garden::Shape::kEllipsoid  ? perception::BushShape::Kind::kEllipsoid
               : object.shape == garden::Shape::kCylinder ? perception::BushShape::Kind::kCylinder
                                                          : perception::BushShape::Kind::kBox;
  shape.size = object.size;
  shape.base_height = object.base_height;
  shape.yaw = object.yaw;
  return shape;
}

}  // namespace

std::vector<stack::Goal> MissionGoals(const Scenario& scenario, const garden::Garden& surveyed) {
  std::vector<stack::Goal> goals;
  for (const ScenarioGoal& goal : scenario.goals) {
    if (goal.bush == 0) {
      goals.emplace_back(goal.position);
      goals.back().yaw = goal.yaw;
      continue;
    }
    const garden::GardenObject& bush = BushOf(surveyed, goal.bush, scenario, ApproachBush(goal.bush));
    if (!goal.trim) {
      goals.push_back(stack::Goal::ApproachBush(bush.position, ShapeOf(bush)));
      goals.back().side = goal.side;
      continue;
    }
    if (bush.object_class != garden::ObjectClass::kTopiary) {
      throw InputError(scenario.source, std::string("goals: ") + (goal.cut ? "trim_bush " : "scan_bush ") +
                                            std::to_string(goal.bush) + ": object " + std::to_string(goal.bush) +
                                            " is a " + garden::ToString(bush.object_class) +
                                            ", not a topiary (only topiaries have a target shape to trim to)");
    }
    goals.push_back(goal.cut ? stack::Goal::TrimBush(bush.position, ShapeOf(bush))
                             : stack::Goal::ScanBush(bush.position, ShapeOf(bush)));
    goals.back().side = goal.side;
  }
  return goals;
}

Pose2 BelievedStart(const Scenario& scenario, std::uint64_t seed) {
  return BelievedPose(scenario.setting.start, scenario.initial_position_sigma, scenario.initial_yaw_sigma, seed);
}

Pose2 BelievedPose(const Pose2& start, double position_sigma, double yaw_sigma, std::uint64_t seed) {
  Rng rng = MakeRng(seed, "initial_pose");
  const double dx = StandardNormal(rng), dy = StandardNormal(rng), dyaw = StandardNormal(rng);
  return {start.x + position_sigma * dx, start.y + position_sigma * dy, WrapAngle(start.yaw + yaw_sigma * dyaw)};
}

namespace {

Eigen::Isometry3d SmallMotion(Rng& rng, double rotation_sigma, double translation_sigma) {
  const auto w = StandardNormalVector<Eigen::Vector3d>(rng);
  const auto t = StandardNormalVector<Eigen::Vector3d>(rng);
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() = RotationFromVector(rotation_sigma * w);
  motion.translation() = translation_sigma * t;
  return motion;
}

}  // namespace

robot::CameraRig CalibratedRig(const robot::CameraRig& truth, const CalibrationError& error) {
  Rng rng = MakeRng(error.seed, "calibration_error");
  std::vector<robot::CameraCalibration> cameras = truth.cameras();
  for (auto& camera : cameras) {
    auto& k = camera.intrinsics;
    const double scale = 1.0 + error.focal_relative * StandardNormal(rng);
    k.fx *= scale;
    k.fy *= scale;
    k.cx += error.principal_point_px * StandardNormal(rng);
    k.cy += error.principal_point_px * StandardNormal(rng);
    const Eigen::Isometry3d motion = SmallMotion(rng, error.rotation_deg * M_PI / 180.0, error.translation_m);
    // cam0's pose on the robot comes from the URDF; the chain to the others is the camchain's.
    if (camera.index > 0) camera.T_base_camera = camera.T_base_camera * motion;
  }
  return robot::CameraRig::FromCameras(cameras, truth.source());
}

double CameraImuTimeOffset(const CalibrationError& error) {
  Rng rng = MakeRng(error.seed, "camera_imu_time_offset");
  return error.camera_imu_time_offset_s * StandardNormal(rng);
}

std::string StackCalibration(const Scenario& scenario, const ProjectPaths& paths, const std::string& dir) {
  const robot::RobotFiles files = paths.robot_files();
  const CalibrationError& error = scenario.calibration_error;
  if (!error.any()) return files.camchain;
  const std::string path = dir + "/stack_camchain.yaml";
  const robot::CameraRig rig = CalibratedRig(robot::LoadCameraRig(files), error);
  WriteFileAtomically(path, robot::CameraRig::FromCameras(rig.cameras(), path).ToKalibrYaml());
  return path;
}

stack::StackParameters StackParametersFor(const Scenario& scenario, const ProjectPaths& paths) {
  const stack::StackParameters defaults = stack::StackParameters::Load(paths.robot_files().stack_parameters);
  const stack::StackParameters parameters = scenario.stack ? defaults.Overridden(*scenario.stack) : defaults;
  if (scenario.simulated_pose_fixes_given &&
      parameters.localization != stack::LocalizationSource::kSimulatedPoseFixes) {
    throw InputError(scenario.source,
                     std::string("simulated_pose_fixes: settings given, but the stack's localization is '") +
                         stack::ToString(parameters.localization) +
                         "' (set stack: {localization: simulated_pose_fixes} to use them)");
  }
  if (parameters.localization == stack::LocalizationSource::kVisual && scenario.visual_map.empty() &&
      !scenario.visual_map_recipe) {
    throw InputError(scenario.source,
                     "the stack's localization is 'visual', but the scenario names no visual_map "
                     "(a map file, or {mapping_drive: PLAN} to build one on first use)");
  }
  return parameters;
}

}  // namespace trimbot::scenarios
