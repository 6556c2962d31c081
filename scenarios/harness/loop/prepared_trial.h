#pragma once
// A scenario's trial, prepared once and passed as a value to whoever needs it: the garden
// file is read once per batch, not once per use. It holds both sides of a trial, and each side
// goes only where it belongs:
//   what the robot is told  - the prior map, the mission, the stack's parameters -> RobotStack
//   the world as it is      - the garden as built                                 -> the simulator
//   the ground truth        - where the goals truly are, the garden on the map's cells -> evaluation
#include <Eigen/Core>
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
  int bush = 0;                                        // garden object id; 0: a point goal
};

struct PreparedTrial {
  garden::Garden garden;                    // the garden file as built (the simulator adds the unmapped objects)
  garden::Garden surveyed;                  // the garden as the survey recorded it (prior_knowledge.h)
  garden::OccupancyMap prior_map;           // the robot's prior map: the surveyed garden's obstacles
  garden::OccupancyMap true_map;            // the garden as it is in the trials, on the prior map's cells
  std::vector<stack::Goal> mission;         // the goals as the stack gets them (bushes as surveyed)
  std::vector<GoalTruth> goal_truths;       // where the goals truly are
  stack::StackParameters stack_parameters;  // robot/config/stack.yaml with the scenario's `stack:`
};

// Reads the scenario's garden and prepares its world. Throws InputError naming the scenario (an
// unknown garden, a goal or arm_reach bush that is not a bush, a survey naming a missing object,
// stack parameters that do not fit the scenario).
PreparedTrial PrepareTrial(const Scenario& scenario, const ProjectPaths& paths);

// The goals' positions as planned (a bush goal: its surveyed centre), for plots.
std::vector<Eigen::Vector2d> GoalPositions(const std::vector<stack::Goal>& goals);

}  // namespace trimbot::scenarios
