#pragma once
// A scenario's trial, prepared once and passed as a value to whoever needs it: the garden
// file is read once per batch, not once per use. It holds both sides of a trial, and each side
// goes only where it belongs:
//   what the robot is told  - the prior map, the mission, the stack's parameters -> RobotStack
//   the world as it is      - the garden as built                                 -> the simulator
//   the ground truth        - where the goals truly are, the garden on the map's cells -> evaluation
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "loop/scenario.h"
#include "loop/setting.h"
#include "trimbot/garden/garden.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/stack/robot_stack.h"

namespace trimbot::scenarios {

// A goal as the evaluation judges it.
struct GoalTruth {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // a point goal's, or the bush's true centre
  std::optional<double> yaw;                           // a point goal's heading (rad), if it has one
  int bush = 0;                                        // garden object id; 0: a point goal
};

struct PreparedTrial {
  garden::Garden garden;                    // the garden file as built (the simulator adds the unmapped objects)
  garden::Garden surveyed;                  // the garden as the survey recorded it (prior_knowledge.h)
  garden::OccupancyMap prior_map;           // the robot's prior map: the surveyed garden's obstacles
  garden::Garden true_garden;               // the garden as it is in the trials: unmapped objects in, foliage grown
  double clearance_height = 0.0;            // m: the robot's top; objects' parts below it are obstacles to it
  garden::OccupancyMap true_map;            // true_garden on the prior map's cells (for plots)
  std::vector<stack::Goal> mission;         // the goals as the stack gets them (bushes as surveyed)
  std::vector<GoalTruth> goal_truths;       // where the goals truly are
  stack::StackParameters stack_parameters;  // robot/config/stack.yaml with the scenario's `stack:`
};

// Reads the scenario's garden and prepares its world. Throws InputError naming the scenario (an
// unknown garden, a goal or arm_reach bush that is not a bush, a survey naming a missing object,
// stack parameters that do not fit the scenario).
PreparedTrial PrepareTrial(const Scenario& scenario, const ProjectPaths& paths);

// A trial's own survey, when the scenario draws one per trial (`survey: {per_trial: true}`): the
// batch's preparation with the surveyed garden, the prior map and the mission drawn again with
// survey seed `trial_seed`.
PreparedTrial WithTrialSurvey(const PreparedTrial& batch, const Scenario& scenario, std::uint64_t trial_seed);

// The goals' positions as planned (a bush goal: its surveyed centre), for plots.
std::vector<Eigen::Vector2d> GoalPositions(const std::vector<stack::Goal>& goals);

}  // namespace trimbot::scenarios
