#include "trimbot/stack/global_planner.h"

#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/terminationconditions/IterationTerminationCondition.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include "trimbot/common/random.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace trimbot::stack {

namespace {

Eigen::Vector2d Point(const ob::State* state) {
  const auto* s = state->as<ob::RealVectorStateSpace::StateType>();
  return {s->values[0], s->values[1]};
}

// A straight motion is valid when base_link keeps its clearance all along it and the footprint,
// pointing along the motion, keeps its margin. Checked every half map cell.
class FootprintMotionValidator : public ob::MotionValidator {
 public:
  FootprintMotionValidator(const ob::SpaceInformationPtr& si, const GlobalPlanner& planner,
                           const Eigen::Vector2d& start)
      : ob::MotionValidator(si), planner_(planner), start_(start) {}

  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    std::pair<ob::State*, double> unused{nullptr, 0.0};
    return checkMotion(s1, s2, unused);
  }
  bool checkMotion(const ob::State* s1, const ob::State* s2, std::pair<ob::State*, double>& last_valid) const override {
    const Eigen::Vector2d a = Point(s1), b = Point(s2);
    const double length = (b - a).norm();
    const double yaw = std::atan2(b.y() - a.y(), b.x() - a.x());
    const auto& p = planner_.parameters();
    const int steps = std::max(1, static_cast<int>(std::ceil(length / (0.5 * planner_.map().resolution()))));
    for (int i = 1; i <= steps; ++i) {
      const double f = static_cast<double>(i) / steps;
      const Eigen::Vector2d q = a + f * (b - a);
      const bool check_footprint = length > 1e-9 && (q - start_).norm() > p.start_footprint_free;
      const bool valid = planner_.Free(q) && (!check_footprint || p.footprint.Clearance(planner_.map(), q.x(), q.y(),
                                                                                        yaw) >= p.footprint_margin);
      if (!valid) {
        const double last = static_cast<double>(i - 1) / steps;
        if (last_valid.first != nullptr) si_->getStateSpace()->interpolate(s1, s2, last, last_valid.first);
        last_valid.second = last;
        invalid_++;
        return false;
      }
    }
    valid_++;
    return true;
  }

 private:
  const GlobalPlanner& planner_;
  Eigen::Vector2d start_;
};

}  // namespace

double Footprint::Clearance(const OccupancyGrid& map, double x, double y, double yaw) const {
  double clearance = std::numeric_limits<double>::infinity();
  for (double cx : circle_x) {
    const Eigen::Vector2d centre(x + cx * std::cos(yaw), y + cx * std::sin(yaw));
    clearance = std::min(clearance, map.DistanceToObstacle(centre) - circle_radius);
  }
  return clearance;
}

void SeedPlanner(std::uint64_t seed) {
  // OMPL takes 32 bits and refuses 0: mix all 64 bits so nearby or 2^32-apart seeds differ.
  const auto mixed = static_cast<std::uint32_t>(SplitMix64(seed) >> 32);
  ompl::RNG::setSeed(mixed == 0 ? 0x9e3779b9u : mixed);
}

GlobalPlanner::GlobalPlanner(const OccupancyGrid& map, const PlannerParameters& parameters)
    : map_(map), parameters_(parameters) {
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
}

bool GlobalPlanner::Free(const Eigen::Vector2d& point) const {
  return map_.DistanceToObstacle(point) >= parameters_.robot_radius;
}

Eigen::Vector2d GlobalPlanner::NearestFree(const Eigen::Vector2d& point, double radius) const {
  return NearestWithClearance(point, parameters_.robot_radius, radius).value_or(point);
}

double GlobalPlanner::ArrivalClearance() const {
  const Footprint& f = parameters_.footprint;
  double reach = 0.0;
  for (double x : f.circle_x) reach = std::max(reach, std::abs(x) + f.circle_radius);
  return std::max(parameters_.robot_radius, reach + parameters_.footprint_margin);
}

std::optional<Eigen::Vector2d> GlobalPlanner::NearestWithClearance(const Eigen::Vector2d& point, double clearance,
                                                                   double radius) const {
  if (map_.DistanceToObstacle(point) >= clearance) return point;
  // Rings of growing radius, 32 directions each: the first point found is the nearest (to within
  // the ring spacing).
  const double step = map_.resolution();
  for (double r = step; r <= radius + 1e-9; r += step) {
    for (int k = 0; k < 32; ++k) {
      const double a = 2.0 * M_PI * k / 32.0;
      const Eigen::Vector2d candidate = point + r * Eigen::Vector2d(std::cos(a), std::sin(a));
      if (map_.DistanceToObstacle(candidate) >= clearance) return candidate;
    }
  }
  return std::nullopt;
}

namespace {

// m: where the planner arrives from when RRT* cannot join the goal itself (GlobalPlanner::Plan).
constexpr double kGoalApproach = 0.4;

// The motion validator's verdict on the straight segment a -> b.
bool Motion(const ob::SpaceInformationPtr& si, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  ob::ScopedState<ob::RealVectorStateSpace> from(si->getStateSpace()), to(si->getStateSpace());
  from[0] = a.x();
  from[1] = a.y();
  to[0] = b.x();
  to[1] = b.y();
  return si->checkMotion(from.get(), to.get());
}

// RRT* from `start` to `goal` on `si`, simplified; nullopt (with the reason in `*message`) when
// the iterations found no exact solution.
std::optional<std::vector<Eigen::Vector2d>> RrtStar(const ob::SpaceInformationPtr& si, const Eigen::Vector2d& start,
                                                    const Eigen::Vector2d& goal, double resolution, double range,
                                                    unsigned iterations, std::string* message) {
  ob::ScopedState<ob::RealVectorStateSpace> from(si->getStateSpace()), to(si->getStateSpace());
  from[0] = start.x();
  from[1] = start.y();
  to[0] = goal.x();
  to[1] = goal.y();
  auto problem = std::make_shared<ob::ProblemDefinition>(si);
  problem->setStartAndGoalStates(from, to, 0.5 * resolution);
  problem->setOptimizationObjective(std::make_shared<ob::PathLengthOptimizationObjective>(si));
  auto planner = std::make_shared<og::RRTstar>(si);
  planner->setRange(range);
  planner->setProblemDefinition(problem);
  planner->setup();
  ob::IterationTerminationCondition budget(iterations);
  const ob::PlannerStatus status = planner->solve(budget);
  if (status != ob::PlannerStatus::EXACT_SOLUTION) {
    if (message != nullptr) {
      *message = std::string("no path found (") + status.asString() + ", " +
                 std::to_string(problem->getSolutionDifference()) + " m short)";
    }
    return std::nullopt;
  }
  auto& path = *problem->getSolutionPath()->as<og::PathGeometric>();
  og::PathSimplifier simplifier(si);
  simplifier.simplifyMax(path);
  std::vector<Eigen::Vector2d> points;
  for (const ob::State* state : path.getStates()) points.push_back(Point(state));
  // RRT* stops within half a cell of the goal: end on the goal itself when that last step is free.
  if (points.back() != goal && Motion(si, points.back(), goal)) points.push_back(goal);
  return points;
}

}  // namespace

PlanResult GlobalPlanner::Plan(const Eigen::Vector2d& start, const Eigen::Vector2d& goal, int attempt) const {
  PlanResult result;
  if (!Free(goal)) {
    result.message = "goal is within " + std::to_string(parameters_.robot_radius) + " m of an obstacle in the map";
    return result;
  }
  // After a drift or a recovery the robot may believe it is inside the clearance: plan from the
  // nearest free point and reach it first.
  const Eigen::Vector2d planning_start = NearestFree(start, parameters_.start_escape_radius);
  if (!Free(planning_start)) {
    result.message = "start is inside an obstacle of the map and no free point is near";
    return result;
  }

  auto space = std::make_shared<ob::RealVectorStateSpace>(2);
  ob::RealVectorBounds bounds(2);
  bounds.setLow(0, map_.origin().x());
  bounds.setLow(1, map_.origin().y());
  bounds.setHigh(0, map_.origin().x() + map_.size().x());
  bounds.setHigh(1, map_.origin().y() + map_.size().y());
  space->setBounds(bounds);

  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([this](const ob::State* state) { return Free(Point(state)); });
  si->setMotionValidator(std::make_shared<FootprintMotionValidator>(si, *this, planning_start));
  si->setup();

  // RRT* joins the goal only from its nearest tree node: a goal that some headings cannot arrive
  // at (the footprint along the last segment) failed a third of the attempts when that node lay on
  // such a side. Then plan to a point near the goal from which the last segment is valid instead.
  const unsigned iterations = static_cast<unsigned>(parameters_.iterations) << std::clamp(attempt, 0, 4);
  const double resolution = map_.resolution(), range = parameters_.range;
  std::optional<std::vector<Eigen::Vector2d>> path =
      RrtStar(si, planning_start, goal, resolution, range, iterations, &result.message);
  for (int k = 0; k < 16 && !path; ++k) {
    const double angle = 2.0 * M_PI * k / 16.0;
    const Eigen::Vector2d before = goal + kGoalApproach * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    if (!Free(before) || !Motion(si, before, goal)) continue;
    path = RrtStar(si, planning_start, before, resolution, range, iterations, nullptr);
    if (path) path->push_back(goal);
  }
  if (!path) return result;
  result.message.clear();
  if (planning_start != start) result.path.push_back(start);
  result.path.insert(result.path.end(), path->begin(), path->end());
  for (std::size_t i = 1; i < result.path.size(); ++i) result.length += (result.path[i] - result.path[i - 1]).norm();
  result.found = true;
  return result;
}

}  // namespace trimbot::stack
