#include "loop/prepared_trial.h"

#include <cmath>
#include <sstream>

#include "loop/prior_knowledge.h"
#include "trimbot/common/input_error.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/robot/robot_description.h"

namespace trimbot::scenarios {
namespace {

// The garden as it is in the trials: its objects, the scenario's unmapped objects, foliage at the
// conditions' growth.
garden::Garden TrueGarden(const Scenario& scenario, const garden::Garden& built) {
  garden::Garden in_trials = built;
  in_trials.AddObjects(scenario.survey.unmapped_objects);
  Survey as_grown;
  as_grown.point_sigma = 0.0;  // the truth, not a survey
  as_grown.growth = scenario.setting.conditions.growth;
  return SurveyedGarden(in_trials, as_grown, scenario.source);
}

// Where each goal truly is: a point goal's position, a bush's true centre (the garden file's object).
std::vector<GoalTruth> GoalTruths(const Scenario& scenario, const garden::Garden& built) {
  std::vector<GoalTruth> truths;
  for (const ScenarioGoal& goal : scenario.goals) {
    const Eigen::Vector2d position =
        goal.bush == 0
            ? goal.position
            : BushOf(built, goal.bush, scenario, "goals: approach_bush " + std::to_string(goal.bush)).position;
    truths.push_back({position, goal.yaw, goal.bush});
  }
  return truths;
}

std::string At(const Eigen::Vector2d& p) {
  std::ostringstream text;
  text.precision(3);
  text << "(" << p.x() << ", " << p.y() << ")";
  return text.str();
}

std::string Named(const garden::GardenObject& object) {
  return "object " + std::to_string(object.id) + " (" + garden::ToString(object.object_class) + ")";
}

// Places the scenario names that cannot be: a start (or a goal with a heading) where the base's
// outline (the URDF's) reaches outside the garden or overlaps an object of the garden as it stands,
// a point goal outside the garden or inside an object. InputError naming the scenario file, the
// start or goal, and the object.
void CheckPlaces(const Scenario& scenario, const garden::Garden& garden, const ProjectPaths& paths, double clearance) {
  const Eigen::Vector2d low = garden.centre - garden.size / 2, high = garden.centre + garden.size / 2;
  const auto outside = [&](const Eigen::Vector2d& p) {
    return (p.array() < low.array()).any() || (p.array() > high.array()).any();
  };
  const auto [min, max] = robot::RobotDescription::Load(paths.robot_files().urdf).BaseOutline();
  const auto check_outline = [&](const std::string& what, const Pose2& pose) {
    constexpr double kStep = 0.02;  // m between the outline's probed points
    for (double x = min.x(); x <= max.x() + 1e-9; x += kStep) {
      for (double y = min.y(); y <= max.y() + 1e-9; y += kStep) {
        const Eigen::Vector2d p =
            Eigen::Vector2d(pose.x, pose.y) + Eigen::Rotation2Dd(pose.yaw) * Eigen::Vector2d(x, y);
        if (outside(p)) {
          throw InputError(scenario.source, what + ": the base at " + At({pose.x, pose.y}) +
                                                " reaches outside the garden '" + garden.name + "'");
        }
        if (const garden::GardenObject* object = garden::ObjectAt(garden, p, clearance)) {
          throw InputError(scenario.source,
                           what + ": the base's outline at " + At({pose.x, pose.y}) + " overlaps " + Named(*object));
        }
      }
    }
  };
  check_outline("start", scenario.setting.start);
  for (std::size_t i = 0; i < scenario.goals.size(); ++i) {
    const ScenarioGoal& goal = scenario.goals[i];
    if (goal.bush != 0) continue;  // a bush goal is checked against the garden's bushes
    const std::string what = "goals[" + std::to_string(i) + "] at " + At(goal.position);
    if (outside(goal.position)) {
      throw InputError(scenario.source, what + " is outside the garden '" + garden.name + "' (x " +
                                            std::to_string(low.x()) + " .. " + std::to_string(high.x()) + ", y " +
                                            std::to_string(low.y()) + " .. " + std::to_string(high.y()) + ")");
    }
    if (const garden::GardenObject* object = garden::ObjectAt(garden, goal.position, clearance)) {
      throw InputError(scenario.source, what + " lies inside " + Named(*object));
    }
    if (goal.yaw)
      check_outline("goals[" + std::to_string(i) + "] with its heading",
                    {goal.position.x(), goal.position.y(), *goal.yaw});
  }
}

}  // namespace

PreparedTrial PrepareTrial(const Scenario& scenario, const ProjectPaths& paths) {
  PreparedTrial prepared;
  // In the order the checks have always run, so that the first problem is the one reported.
  prepared.stack_parameters = StackParametersFor(scenario, paths);
  prepared.garden = LoadGarden(scenario.setting, paths);
  const double clearance_height = MapClearanceHeight(scenario, paths);
  if (!scenario.arm_reach) {
    garden::Garden in_trials = prepared.garden;  // with the objects the survey missed
    in_trials.AddObjects(scenario.survey.unmapped_objects);
    CheckPlaces(scenario, in_trials, paths, clearance_height);
  }
  prepared.surveyed = SurveyedGarden(prepared.garden, scenario.survey, scenario.source);
  prepared.prior_map = PriorMap(scenario, prepared.surveyed, clearance_height);
  prepared.mission = MissionGoals(scenario, prepared.surveyed);
  if (scenario.arm_reach) {
    BushOf(prepared.garden, scenario.arm_reach->bush, scenario,
           "arm_reach: bush " + std::to_string(scenario.arm_reach->bush));
  }
  prepared.goal_truths = GoalTruths(scenario, prepared.garden);
  prepared.true_garden = TrueGarden(scenario, prepared.garden);
  prepared.clearance_height = clearance_height;
  prepared.true_map = garden::MakeOccupancyMap(prepared.true_garden, scenario.map_resolution, clearance_height);
  return prepared;
}

PreparedTrial WithTrialSurvey(const PreparedTrial& batch, const Scenario& scenario, std::uint64_t trial_seed) {
  Survey survey = scenario.survey;
  survey.seed = trial_seed;
  PreparedTrial trial = batch;
  trial.surveyed = SurveyedGarden(trial.garden, survey, scenario.source);
  trial.prior_map = PriorMap(scenario, trial.surveyed, trial.clearance_height);
  trial.mission = MissionGoals(scenario, trial.surveyed);
  return trial;
}

std::vector<Eigen::Vector2d> GoalPositions(const std::vector<stack::Goal>& goals) {
  std::vector<Eigen::Vector2d> positions;
  for (const stack::Goal& goal : goals) positions.push_back(goal.position);
  return positions;
}

}  // namespace trimbot::scenarios
