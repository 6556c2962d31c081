#include "loop/trial_world.h"

#include "loop/prior_knowledge.h"

namespace trimbot::scenarios {
namespace {

// The garden as it is in the trials - its objects, the scenario's unmapped objects, foliage at the
// conditions' growth - on the prior map's cells (for plots and clearance: what the robot's map lacks).
garden::OccupancyMap TrueMap(const Scenario& scenario, const garden::Garden& built) {
  garden::Garden world = built;
  world.AddObjects(scenario.survey.unmapped_objects);
  Survey as_grown;
  as_grown.growth = scenario.world.conditions.growth;
  return garden::MakeOccupancyMap(SurveyedGarden(world, as_grown, scenario.source), scenario.map_resolution,
                                  scenario.map_clearance_height);
}

// Where each goal truly is: a point goal's position, a bush's true centre (the garden file's object).
std::vector<GoalTruth> GoalTruths(const Scenario& scenario, const garden::Garden& built) {
  std::vector<GoalTruth> truths;
  for (const ScenarioGoal& goal : scenario.goals) {
    const Eigen::Vector2d position =
        goal.bush == 0
            ? goal.position
            : BushOf(built, goal.bush, scenario, "goals: approach_bush " + std::to_string(goal.bush)).position;
    truths.push_back({position, goal.bush});
  }
  return truths;
}

}  // namespace

TrialWorld PrepareTrialWorld(const Scenario& scenario, const ProjectPaths& paths) {
  TrialWorld world;
  // In the order the checks have always run, so that the first problem is the one reported.
  world.stack_parameters = StackParametersFor(scenario, paths);
  world.garden = garden::Garden::Load(ResolveGarden(scenario.world, paths));
  world.surveyed = SurveyedGarden(world.garden, scenario.survey, scenario.source);
  world.prior_map = PriorMap(scenario, world.surveyed);
  world.mission = MissionGoals(scenario, world.surveyed);
  if (scenario.arm_reach) {
    BushOf(world.garden, scenario.arm_reach->bush, scenario,
           "arm_reach: bush " + std::to_string(scenario.arm_reach->bush));
  }
  world.goal_truths = GoalTruths(scenario, world.garden);
  world.true_map = TrueMap(scenario, world.garden);
  return world;
}

std::vector<Eigen::Vector2d> GoalPositions(const std::vector<stack::Goal>& goals) {
  std::vector<Eigen::Vector2d> positions;
  for (const stack::Goal& goal : goals) positions.push_back(goal.position);
  return positions;
}

}  // namespace trimbot::scenarios
