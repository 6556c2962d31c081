#include "loop/prepared_trial.h"

#include "loop/prior_knowledge.h"

namespace trimbot::scenarios {
namespace {

// The garden as it is in the trials - its objects, the scenario's unmapped objects, foliage at the
// conditions' growth - on the prior map's cells (for plots and clearance: what the robot's map lacks).
garden::OccupancyMap TrueMap(const Scenario& scenario, const garden::Garden& built) {
  garden::Garden in_trials = built;
  in_trials.AddObjects(scenario.survey.unmapped_objects);
  Survey as_grown;
  as_grown.point_sigma = 0.0;  // the truth, not a survey
  as_grown.growth = scenario.setting.conditions.growth;
  return garden::MakeOccupancyMap(SurveyedGarden(in_trials, as_grown, scenario.source), scenario.map_resolution,
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

PreparedTrial PrepareTrial(const Scenario& scenario, const ProjectPaths& paths) {
  PreparedTrial prepared;
  // In the order the checks have always run, so that the first problem is the one reported.
  prepared.stack_parameters = StackParametersFor(scenario, paths);
  prepared.garden = LoadGarden(scenario.setting, paths);
  prepared.surveyed = SurveyedGarden(prepared.garden, scenario.survey, scenario.source);
  prepared.prior_map = PriorMap(scenario, prepared.surveyed);
  prepared.mission = MissionGoals(scenario, prepared.surveyed);
  if (scenario.arm_reach) {
    BushOf(prepared.garden, scenario.arm_reach->bush, scenario,
           "arm_reach: bush " + std::to_string(scenario.arm_reach->bush));
  }
  prepared.goal_truths = GoalTruths(scenario, prepared.garden);
  prepared.true_map = TrueMap(scenario, prepared.garden);
  return prepared;
}

std::vector<Eigen::Vector2d> GoalPositions(const std::vector<stack::Goal>& goals) {
  std::vector<Eigen::Vector2d> positions;
  for (const stack::Goal& goal : goals) positions.push_back(goal.position);
  return positions;
}

}  // namespace trimbot::scenarios
