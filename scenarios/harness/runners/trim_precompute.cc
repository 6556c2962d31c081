#include "runners/trim_precompute.h"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "runners/exit_code.h"
#include "trimbot/common/input_error.h"
#include "trimbot/robot/collision_model.h"
#include "trimbot/robot/robot_parameters.h"
#include "trimbot/stack/stack_parameters.h"
#include "trimbot/trimming/plan_database.h"

namespace trimbot::scenarios {
namespace {

// The exponents of the garden's topiary shapes (garden_scenes' TargetShape): ball, cylinder with
// rounded rims, box with rounded edges.
perception::TopiaryShape ShapeNamed(const std::string& name) {
  perception::TopiaryShape shape;
  if (name == "ball") return shape;
  if (name == "cylinder") {
    shape.vertical_exponent = 6.0;
    return shape;
  }
  if (name == "box") {
    shape.horizontal_exponent = shape.vertical_exponent = 6.0;
    return shape;
  }
  throw InputError("--shapes", "unknown shape '" + name + "' (ball, cylinder or box)");
}

}  // namespace

int RunTrimPrecompute(const TrimPrecomputeOptions& options, const ProjectPaths& paths) {
  for (double size : options.sizes) {
    if (!(size >= 0.2 && size <= 2.0)) throw InputError("--sizes", "size " + std::to_string(size) + " m: 0.2-2 m");
  }
  for (double distance : options.distances) {
    if (!(distance >= 0.3 && distance <= 3.0))
      throw InputError("--distances", "distance " + std::to_string(distance) + " m: 0.3-3 m");
  }
  std::vector<perception::TopiaryShape> shapes;
  for (const std::string& name : options.shapes) shapes.push_back(ShapeNamed(name));
  const robot::RobotFiles files = paths.robot_files();
  const robot::RobotDescription robot = robot::RobotDescription::Load(files.urdf);
  const arm::ArmKinematics kinematics(robot);
  const auto parameters = robot::RobotParameters::Load(files.robot_parameters);
  const Eigen::VectorXd home = Eigen::Map<const Eigen::VectorXd>(parameters.arm_home_position.data(), 6);
  const Eigen::Isometry3d T_cutter_blade = robot.BladeInCutter();
  // The stack's own: stored paths are the ones it would plan.
  const trimming::TrimParameters trim = stack::StackParameters::Load(files.stack_parameters).Trim();
  robot::CollisionModel collision(robot, robot.ArmJointNames(), trim.planner.body_clearance);
  trimming::CuttingPathOptions path_options = trim.PathOptions();
  path_options.search = trimming::GtspSearchOptions{};  // offline: GLNS's default mode in full
  trimming::CuttingPathDatabase database;
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    for (double size : options.sizes) {
      for (double distance : options.distances) {
        for (double bearing : options.bearings_deg) {
          perception::TopiaryShape target = shapes[s];
          target.half = Eigen::Vector3d::Constant(0.5 * size);
          const double b = bearing * M_PI / 180.0;
          target.centre = {distance * std::cos(b), distance * std::sin(b), target.half.z()};
          const auto start = std::chrono::steady_clock::now();
          const trimming::CuttingChecks checks = trimming::MakeCuttingChecks(
              kinematics, T_cutter_blade, &collision, target,
              trimming::CheckDepth(target, 0.0, trim.poses.spacing, robot.BladeThickness()), trim.planner);
          const trimming::CuttingPath path =
              trimming::PlanCuttingPath(kinematics, T_cutter_blade, home, trimming::CuttingPoses(target, trim.poses),
                                        checks.valid, checks.free_move, path_options);
          const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          std::printf("[trim] %s %.2f m at %.2f m, %+.0f deg: ", options.shapes[s].c_str(), size, distance, bearing);
          if (!path.ok) {
            std::printf("not stored: %s\n", path.failure.c_str());
            continue;
          }
          std::printf("%d poses reached (%zu not), tour %.1f s (nearest neighbour %.1f s), planned in %.1f s\n",
                      path.clusters, path.unreachable.size(), path.motion_time, path.nearest_neighbour_time, seconds);
          database.Add(trimming::ToStored(path, target));
        }
      }
    }
  }
  database.Save(options.out, trimming::ArmSignature(kinematics, T_cutter_blade));
  std::printf("[trim] %d cutting paths in %s\n", database.size(), options.out.c_str());
  return kExitSuccess;
}

}  // namespace trimbot::scenarios
