#pragma once
// What the robot knows before a trial, made from the scenario and the world honestly: the prior
// map from the garden as surveyed (not the simulated geometry), where it was put down (the true
// start plus the scenario's placement error), the calibration file it reads (the true one plus
// the scenario's calibration error), and its software's parameters (robot/config/stack.yaml with
// the scenario's `stack:` overrides). The simulator never sees any of these.
#include <cstdint>
#include <string>
#include <vector>

#include "eval/trial_evaluator.h"
#include "runner/scenario.h"
#include "runner/world_setup.h"
#include "trimbot/garden/garden.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/stack/robot_stack.h"

namespace trimbot::scenarios {

// The garden as the survey recorded it: foliage at the survey's growth, unmapped objects left
// out, objects that are gone still in. Throws InputError (naming the scenario) for an unknown id.
garden::Garden SurveyedGarden(const garden::Garden& built, const Survey& survey, const std::string& scenario_file);

// The robot's prior map: the surveyed garden's objects below the clearance height.
garden::OccupancyMap PriorMap(const Scenario& scenario, const ProjectPaths& paths);
// The garden as it is in the trial's world - its objects, the scenario's unmapped objects, foliage
// at the conditions' growth - on the prior map's cells (for plots: what the robot's map lacks).
garden::OccupancyMap WorldMap(const Scenario& scenario, const ProjectPaths& paths);
// Writes it (map_server) as <dir>/map.{png,yaml}; returns the YAML's path.
std::string WritePriorMap(const garden::OccupancyMap& map, const std::string& dir);

// The mission as the stack gets it: point goals as given; bush goals with the bush as surveyed
// (centre, shape, yaw). Throws InputError naming the scenario for a bush the surveyed garden lacks
// or an object that is not a bush (topiary or rose).
std::vector<stack::Goal> MissionGoals(const Scenario& scenario, const ProjectPaths& paths);
// An arm_reach scenario's bush is a bush of the garden; InputError naming the scenario otherwise.
void CheckArmReach(const Scenario& scenario, const ProjectPaths& paths);
// Where each goal truly is, for the evaluation: a point goal's position, a bush's true centre in
// the world (the garden file's object), with the bush's id.
std::vector<GoalTruth> GoalTruths(const Scenario& scenario, const ProjectPaths& paths);
// The goals' positions as planned (a bush goal: its surveyed centre), for plots.
std::vector<Eigen::Vector2d> GoalPositions(const std::vector<stack::Goal>& goals);

// Where the operator believes the robot stands: the true start with seeded placement error.
stack::Pose2 BelievedStart(const Scenario& scenario, std::uint64_t seed);

// The camchain the stack reads: the true calibration, or with the scenario's seeded calibration
// error written to <dir>/stack_camchain.yaml. Returns the file's path.
std::string StackCalibration(const Scenario& scenario, const ProjectPaths& paths, std::uint64_t seed,
                             const std::string& dir);

// The stack's parameters for this scenario. Throws InputError naming the file and key.
stack::StackParameters StackParametersFor(const Scenario& scenario, const ProjectPaths& paths);

}  // namespace trimbot::scenarios
