#pragma once
// What the robot knows before a trial, made from the scenario and the world honestly: the prior
// map from the garden as surveyed (not the simulated geometry), where it was put down (the true
// start plus the scenario's placement error), the calibration file it reads (the true one plus
// the scenario's calibration error), and its software's parameters (robot/config/stack.yaml with
// the scenario's `stack:` overrides). The simulator never sees any of these.
#include <cstdint>
#include <string>
#include <vector>

#include "loop/scenario.h"
#include "loop/setting.h"
#include "trimbot/garden/garden.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/stack/robot_stack.h"

namespace trimbot::scenarios {

// The garden as the survey recorded it: foliage at the survey's growth, every object with the
// survey's seeded errors (position, extents, yaw), unmapped objects left out, objects that are gone
// still in (as the scenario gives them). Throws InputError (naming the scenario) for an unknown id.
garden::Garden SurveyedGarden(const garden::Garden& built, const Survey& survey, const std::string& scenario_file);

// The height below which objects are obstacles: the scenario's `map: clearance_height`, or else the
// robot's top with its arm at home (URDF, robot_parameters.yaml) plus 5 cm - what passes under a
// tree crown and what does not.
double MapClearanceHeight(const Scenario& scenario, const ProjectPaths& paths);
// The robot's top with its arm at home plus 5 cm (the default of MapClearanceHeight).
double RobotClearanceHeight(const ProjectPaths& paths);
// The robot's prior map: the surveyed garden's objects' parts below `clearance_height`.
garden::OccupancyMap PriorMap(const Scenario& scenario, const garden::Garden& surveyed, double clearance_height);
// Writes it (map_server) as <dir>/map.{png,yaml}; returns the YAML's path.
std::string WritePriorMap(const garden::OccupancyMap& map, const std::string& dir);

// The mission as the stack gets it: point goals as given; bush goals with the bush as surveyed
// (centre, shape, yaw). Throws InputError naming the scenario for a bush the surveyed garden lacks
// or an object that is not a bush (topiary or rose).
std::vector<stack::Goal> MissionGoals(const Scenario& scenario, const garden::Garden& surveyed);
// Object `id` of `garden`, which must be a bush (topiary or rose); InputError naming the scenario
// and `what` (where the id was given, e.g. "goals: approach_bush 3") otherwise.
const garden::GardenObject& BushOf(const garden::Garden& garden, int id, const Scenario& scenario,
                                   const std::string& what);

// Where the operator believes the robot stands: the true start with seeded placement error.
Pose2 BelievedStart(const Scenario& scenario, std::uint64_t seed);
// The same for any start: `start` + seeded noise of these sigmas (m per axis, rad).
Pose2 BelievedPose(const Pose2& start, double position_sigma, double yaw_sigma, std::uint64_t seed);

// The camchain the stack reads: the true calibration, or with the scenario's seeded calibration
// error written to <dir>/stack_camchain.yaml. Returns the file's path.
// The calibration the robot's stack reads: the true rig with the calibration's seeded errors.
robot::CameraRig CalibratedRig(const robot::CameraRig& truth, const CalibrationError& error);
// The cameras' clock against the IMU's (s, SimulatorConfig::camera_time_offset): the calibration's
// residual, seeded alike; the stack assumes 0.
double CameraImuTimeOffset(const CalibrationError& error);

// The camchain the stack reads: the true calibration, or with the scenario's calibration error
// written to <dir>/stack_camchain.yaml. Returns the file's path.
std::string StackCalibration(const Scenario& scenario, const ProjectPaths& paths, const std::string& dir);

// The stack's parameters for this scenario. Throws InputError naming the file and key.
stack::StackParameters StackParametersFor(const Scenario& scenario, const ProjectPaths& paths);

}  // namespace trimbot::scenarios
