#include "trimbot/stack/global_planner.h"

#include <ompl/base/Goal.h>
#include <ompl/base/OptimizationObjective.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/base/terminationconditions/IterationTerminationCondition.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>
#include <boost/graph/compressed_sparse_row_graph.hpp>
#include <boost/graph/dijkstra_shortest_paths.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "trimbot/common/pose2.h"
#include "trimbot/common/random.h"

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace trimbot::stack {

namespace {

constexpr int kHeadings = 32;  // headings tried where a pose must fit (goals, escapes)

// To [-pi, pi), OMPL's SO(2) bounds.
double OmplYaw(double angle) {
  const double wrapped = WrapAngle(angle);
  return wrapped >= M_PI ? wrapped - 2.0 * M_PI : wrapped;
}

Pose2 ToPose(const ob::State* state) {
  const auto* s = state->as<ob::SE2StateSpace::StateType>();
  return {s->getX(), s->getY(), s->getYaw()};
}

void SetPose(const Pose2& pose, ob::State* state) {
  auto* s = state->as<ob::SE2StateSpace::StateType>();
  s->setXY(pose.x, pose.y);
  s->setYaw(OmplYaw(pose.yaw));
}

// The clearance each pose of a plan must keep: min_clearance, except near the start, where the
// robot may stand closer after a stop and must only get no closer than it is.
class ClearanceRule {
 public:
  ClearanceRule(const GlobalPlanner& planner, const Pose2& start) : planner_(planner), start_(start.x, start.y) {
    const double at_start = planner.Clearance(start, planner.parameters().min_clearance);
    near_start_ = std::min(planner.parameters().min_clearance, at_start - 1e-3);
  }
  // min_clearance everywhere (no start to be exempt near).
  explicit ClearanceRule(const GlobalPlanner& planner)
      : planner_(planner), start_(Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity())) {}
  double At(const Eigen::Vector2d& position) const {
    return (position - start_).norm() < planner_.parameters().start_free_radius ? near_start_
                                                                                : planner_.parameters().min_clearance;
  }

 private:
  const GlobalPlanner& planner_;
  Eigen::Vector2d start_;
  double near_start_ = 0.0;
};

// Whether the outline keeps `wanted` along the straight motion from `from` to `to` at `heading`,
// given lower bounds of its clearance at both ends. The clearance changes by at most the distance
// moved, so an interval whose ends' bound (c0 + c1 - length) / 2 reaches `wanted` is clear;
// otherwise it is split, down to 1 mm (where the ends' own clearances decide).
bool StraightClear(const GlobalPlanner& planner, const ClearanceRule& rule, const Eigen::Vector2d& from,
                   const Eigen::Vector2d& to, double heading, double c0, double c1) {
  const double length = (to - from).norm();
  const double wanted = std::max(rule.At(from), rule.At(to));
  if (c0 < rule.At(from) || c1 < rule.At(to)) return false;
  if (0.5 * (c0 + c1 - length) >= wanted) return true;
  if (length < 1e-3) return true;
  const Eigen::Vector2d middle = 0.5 * (from + to);
  const double c = planner.Clearance({middle.x(), middle.y(), heading}, wanted + 0.5 * length);
  return StraightClear(planner, rule, from, middle, heading, c0, c) &&
         StraightClear(planner, rule, middle, to, heading, c, c1);
}

// Whether the drive's motion a -> b (turn to face b, straight, turn to b's heading) keeps the
// rule's clearance at every pose: the straight part sampled every half cell and then exactly
// (StraightClear), the turns every half cell of the outline's farthest corner's travel.
bool MotionClear(const GlobalPlanner& planner, const ClearanceRule& rule, const Pose2& a, const Pose2& b) {
  const OccupancyGrid& map = planner.map();
  const BaseOutline& outline = planner.outline();
  const double step = 0.5 * map.resolution();
  const Eigen::Vector2d from(a.x, a.y), to(b.x, b.y);
  const double length = (to - from).norm();
  if (length < 1e-9) return outline.TurnClearance(map, a, b.yaw, step, rule.At(from)) >= rule.At(from);
  const double heading = std::atan2(to.y() - from.y(), to.x() - from.x());
  if (outline.TurnClearance(map, a, heading, step, rule.At(from)) < rule.At(from)) return false;
  const int steps = std::max(1, static_cast<int>(std::ceil(length / step)));
  const double piece = length / steps;
  Eigen::Vector2d previous = from;
  double previous_clearance = planner.Clearance({from.x(), from.y(), heading}, rule.At(from) + piece);
  for (int k = 1; k <= steps; ++k) {
    const Eigen::Vector2d q = from + (static_cast<double>(k) / steps) * (to - from);
    const double clearance = planner.Clearance({q.x(), q.y(), heading}, rule.At(q) + piece);
    if (!StraightClear(planner, rule, previous, q, heading, previous_clearance, clearance)) return false;
    previous = q;
    previous_clearance = clearance;
  }
  return outline.TurnClearance(map, {b.x, b.y, heading}, b.yaw, step, rule.At(to)) >= rule.At(to);
}

class DriveMotionValidator : public ob::MotionValidator {
 public:
  DriveMotionValidator(const ob::SpaceInformationPtr& si, const GlobalPlanner& planner, const ClearanceRule& rule)
      : ob::MotionValidator(si), planner_(planner), rule_(rule) {}

  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    const bool valid = MotionClear(planner_, rule_, ToPose(s1), ToPose(s2));
    (valid ? valid_ : invalid_)++;
    return valid;
  }
  bool checkMotion(const ob::State* s1, const ob::State* s2, std::pair<ob::State*, double>& last_valid) const override {
    // Only the verdict is used by the planners run here (RRT*, the simplifier); report no progress.
    const bool valid = checkMotion(s1, s2);
    if (!valid) {
      if (last_valid.first != nullptr) si_->copyState(last_valid.first, s1);
      last_valid.second = 0.0;
    }
    return valid;
  }

 private:
  const GlobalPlanner& planner_;
  const ClearanceRule& rule_;
};

// Path cost: the drive's motion cost (GlobalPlanner::MotionCost); the straight distance is its
// admissible heuristic.
class DriveObjective : public ob::OptimizationObjective {
 public:
  DriveObjective(const ob::SpaceInformationPtr& si, const GlobalPlanner& planner)
      : ob::OptimizationObjective(si), planner_(planner) {
    description_ = "drive time and clearance";
  }
  ob::Cost stateCost(const ob::State*) const override { return identityCost(); }
  ob::Cost motionCost(const ob::State* s1, const ob::State* s2) const override {
    return ob::Cost(planner_.MotionCost(ToPose(s1), ToPose(s2)));
  }
  ob::Cost motionCostHeuristic(const ob::State* s1, const ob::State* s2) const override {
    const Pose2 a = ToPose(s1), b = ToPose(s2);
    return ob::Cost(std::hypot(b.x - a.x, b.y - a.y));
  }

 private:
  const GlobalPlanner& planner_;
};

}  // namespace

void SeedPlanner(std::uint64_t seed) {
  // OMPL takes 32 bits and refuses 0: mix all 64 bits so nearby or 2^32-apart seeds differ.
  const auto mixed = static_cast<std::uint32_t>(SplitMix64(seed) >> 32);
  ompl::RNG::setSeed(mixed == 0 ? 0x9e3779b9u : mixed);
}

GlobalPlanner::GlobalPlanner(const OccupancyGrid& map, const BaseOutline& outline, const PlannerParameters& parameters)
    : map_(map), outline_(outline), parameters_(parameters) {
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
}

double GlobalPlanner::Clearance(const Pose2& pose, double enough) const {
  return outline_.Clearance(map_, pose, enough);
}

bool GlobalPlanner::Valid(const Pose2& pose) const {
  return Clearance(pose, parameters_.min_clearance) >= parameters_.min_clearance;
}

namespace {

// The headings a goal may be arrived at: `yaw` if given, else kHeadings round.
std::vector<double> GoalHeadings(std::optional<double> yaw) {
  if (yaw) return {OmplYaw(*yaw)};
  std::vector<double> headings;
  for (int k = 0; k < kHeadings; ++k) headings.push_back(OmplYaw(2.0 * M_PI * k / kHeadings));
  return headings;
}

// Of the goal headings at `position`, the one with the most clearance and that clearance.
std::pair<double, double> BestHeading(const GlobalPlanner& planner, const Eigen::Vector2d& position,
                                      std::optional<double> yaw = std::nullopt) {
  std::pair<double, double> best{0.0, -std::numeric_limits<double>::infinity()};
  for (const double heading : GoalHeadings(yaw)) {
    const double clearance = planner.Clearance({position.x(), position.y(), heading});
    if (clearance > best.second) best = {heading, clearance};
  }
  return best;
}

// Whether the base can turn all the way round at `pose`: the disc its farthest corner sweeps keeps
// min_clearance (exact for a full turn, conservative for part of one).
bool CanTurnRound(const GlobalPlanner& planner, const Pose2& pose) {
  // The distance is to the nearest occupied cell's centre; its square reaches half a diagonal nearer.
  const OccupancyGrid& map = planner.map();
  return map.DistanceToObstacle({pose.x, pose.y}) - M_SQRT1_2 * map.resolution() >=
         planner.outline().reach() + planner.parameters().min_clearance;
}

// Where the drive can come from to arrive at `at` going forwards: walking back along its heading
// (every two cells, up to `max_run`) while the outline keeps the rule's clearance, the first pose
// where the base can turn round. A goal beside a wall is reached by such a run along the wall;
// nothing else (forward turn-drive-turn motions) can arrive there.
std::optional<Pose2> TurnableApproach(const GlobalPlanner& planner, const ClearanceRule& rule, const Pose2& at,
                                      double max_run) {
  const double step = 2.0 * planner.map().resolution();
  const Eigen::Vector2d back(-std::cos(at.yaw), -std::sin(at.yaw));
  Pose2 previous = at;
  for (double d = step; d <= max_run + 1e-9; d += step) {
    const Pose2 p{at.x + d * back.x(), at.y + d * back.y(), at.yaw};
    if (!planner.Valid(p) || !MotionClear(planner, rule, p, previous)) return std::nullopt;  // the run is blocked
    if (CanTurnRound(planner, p)) return p;
    previous = p;
  }
  return std::nullopt;
}

constexpr double kMaxApproachRun = 4.0;  // m: the longest straight run into a goal the planner looks for

// Whether the drive can arrive at `position` going forwards: some heading where the outline fits
// and the base either turns round there or has a straight run into it from where it can
// (TurnableApproach). A pose that fits only backing in, or only with a turn that the obstacles
// around it forbid, is not a goal the drive can reach.
bool Enterable(const GlobalPlanner& planner, const Eigen::Vector2d& position, std::optional<double> yaw) {
  const ClearanceRule rule(planner);
  for (const double heading : GoalHeadings(yaw)) {
    const Pose2 at{position.x(), position.y(), heading};
    if (!planner.Valid(at)) continue;
    if (CanTurnRound(planner, at) || TurnableApproach(planner, rule, at, kMaxApproachRun)) return true;
  }
  return false;
}

double PathCost(const GlobalPlanner& planner, const std::vector<Pose2>& poses) {
  double cost = 0.0;
  for (std::size_t i = 1; i < poses.size(); ++i) cost += planner.MotionCost(poses[i - 1], poses[i]);
  return cost;
}

// RRT* stops after a fixed number of iterations, often on a detour (round a bush instead of along
// the open lane beside it, a zig-zag where a straight run would do). Shortcutting removes them:
// first from each vertex to the farthest vertex it reaches directly; then between two points drawn
// along the path (OMPL's seeded generator), each with the heading of its straight piece. A
// turn-drive-turn motion's straight part is still valid when cut short at the same heading, so only
// the new motion between the two points needs checking - unlike OMPL's own shortcutting, which
// interpolates headings and would skip the turns. Kept only where the path's cost falls.
void Shortcut(const GlobalPlanner& planner, const ClearanceRule& rule, std::vector<Pose2>* path) {
  std::vector<Pose2>& poses = *path;
  for (std::size_t i = 0; i + 2 < poses.size(); ++i) {
    for (std::size_t j = poses.size() - 1; j > i + 1; --j) {
      double via = 0.0;
      for (std::size_t k = i + 1; k <= j; ++k) via += planner.MotionCost(poses[k - 1], poses[k]);
      if (planner.MotionCost(poses[i], poses[j]) < via && MotionClear(planner, rule, poses[i], poses[j])) {
        poses.erase(poses.begin() + static_cast<std::ptrdiff_t>(i) + 1, poses.begin() + static_cast<std::ptrdiff_t>(j));
        break;
      }
    }
  }
  ompl::RNG rng;
  const int attempts = 20 * static_cast<int>(poses.size());
  for (int attempt = 0; attempt < attempts && poses.size() >= 3; ++attempt) {
    // Two points on different straight pieces: piece i (from pose i to i + 1) at fraction a.
    std::size_t i = static_cast<std::size_t>(rng.uniformInt(0, static_cast<int>(poses.size()) - 2));
    std::size_t j = static_cast<std::size_t>(rng.uniformInt(0, static_cast<int>(poses.size()) - 2));
    if (i == j) continue;
    if (i > j) std::swap(i, j);
    const auto on_piece = [&](std::size_t k, double f) {
      const Pose2& a = poses[k];
      const Pose2& b = poses[k + 1];
      const double heading = std::hypot(b.x - a.x, b.y - a.y) > 1e-9 ? std::atan2(b.y - a.y, b.x - a.x) : a.yaw;
      return Pose2{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), heading};
    };
    const Pose2 p = on_piece(i, rng.uniform01()), q = on_piece(j, rng.uniform01());
    std::vector<Pose2> candidate(poses.begin(), poses.begin() + static_cast<std::ptrdiff_t>(i) + 1);
    candidate.push_back(p);
    candidate.push_back(q);
    candidate.insert(candidate.end(), poses.begin() + static_cast<std::ptrdiff_t>(j) + 1, poses.end());
    if (PathCost(planner, candidate) < PathCost(planner, poses) - 1e-6 && MotionClear(planner, rule, p, q)) {
      poses = std::move(candidate);
    }
  }
}

// Of the cells within 0.5 m of `goal`, the index (row * cols + column) of the one nearest it that
// Dijkstra reached (`distance` finite), or -1.
int NearestReached(const OccupancyGrid& map, const std::vector<double>& distance, const Eigen::Vector2d& goal) {
  const int rows = map.occupied().rows, cols = map.occupied().cols;
  const cv::Point to = map.Cell(goal);
  int target = -1;
  double nearest = std::numeric_limits<double>::infinity();
  const int reach = static_cast<int>(std::ceil(0.5 / map.resolution()));
  for (int r = std::max(0, to.y - reach); r <= std::min(rows - 1, to.y + reach); ++r) {
    for (int c = std::max(0, to.x - reach); c <= std::min(cols - 1, to.x + reach); ++c) {
      const double reached = distance[static_cast<std::size_t>(r * cols + c)];
      if (!std::isfinite(reached) || reached == std::numeric_limits<double>::max()) continue;
      const double d = (map.CellCentre({c, r}) - goal).norm();
      if (d < nearest) {
        nearest = d;
        target = r * cols + c;
      }
    }
  }
  return target;
}

// The cheapest route for base_link over the map's cells (Dijkstra, Boost.Graph), where the outline
// fits sideways (a cell's distance to the nearest obstacle less half the base's width keeps the
// rule's clearance), each step costed as MotionCost costs clearance: the cells' centres from the
// start to the goal's cell (or the reached cell nearest the goal). Empty when there is none.
std::vector<Eigen::Vector2d> RouteCells(const GlobalPlanner& planner, const ClearanceRule& rule, const Pose2& start,
                                        const Eigen::Vector2d& goal) {
  const OccupancyGrid& map = planner.map();
  const PlannerParameters& parameters = planner.parameters();
  const int rows = map.occupied().rows, cols = map.occupied().cols;
  const double half_width = 0.5 * planner.outline().width();
  const auto index = [cols](int r, int c) { return r * cols + c; };
  const cv::Point from = map.Cell({start.x, start.y}), to = map.Cell(goal);
  const auto inside = [&](const cv::Point& p) { return p.x >= 0 && p.y >= 0 && p.x < cols && p.y < rows; };
  if (!inside(from) || !inside(to)) return {};
  // Near the start (after a stop the robot may stand closer than min_clearance) a cell need only
  // be no closer than the start's.
  // Distances between cell centres; the occupied cell's square reaches half a cell nearer.
  const double to_square = 0.5 * map.resolution();
  const double at_start = map.DistanceToObstacleAtCell(map.CellCentre(from)) - to_square - half_width;
  std::vector<double> clearance(static_cast<std::size_t>(rows) * cols);
  std::vector<char> free(clearance.size(), 0);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector2d centre = map.CellCentre({c, r});
      const double d = map.DistanceToObstacleAtCell(centre) - to_square - half_width;
      const bool near_start = (centre - Eigen::Vector2d(start.x, start.y)).norm() < parameters.start_free_radius;
      clearance[index(r, c)] = d;
      free[index(r, c)] = d >= (near_start ? std::min(rule.At(centre), at_start) : rule.At(centre)) ? 1 : 0;
    }
  }
  free[index(from.y, from.x)] = 1;
  struct Edge {
    double cost;
  };
  std::vector<std::pair<int, int>> edges;
  std::vector<Edge> costs;
  const double preferred = parameters.preferred_clearance;
  const auto step_cost = [&](int a, int b, double length) {
    const double d = 0.5 * (clearance[a] + clearance[b]);
    const double penalty = preferred > 0.0 ? std::max(0.0, 1.0 - d / preferred) : 0.0;
    return length * (1.0 + parameters.clearance_cost * penalty);
  };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (!free[index(r, c)]) continue;
      for (const auto& [dr, dc] : {std::pair{0, 1}, {1, 0}, {1, 1}, {1, -1}}) {
        const int r2 = r + dr, c2 = c + dc;
        if (r2 >= rows || c2 < 0 || c2 >= cols || !free[index(r2, c2)]) continue;
        if (dr != 0 && dc != 0 && (!free[index(r, c2)] || !free[index(r2, c)])) continue;  // no corner cutting
        const double length = map.resolution() * std::hypot(dr, dc);
        for (const auto& [a, b] : {std::pair{index(r, c), index(r2, c2)}, {index(r2, c2), index(r, c)}}) {
          edges.emplace_back(a, b);
          costs.push_back({step_cost(a, b, length)});
        }
      }
    }
  }
  using Graph = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, Edge>;
  const Graph graph(boost::edges_are_unsorted_multi_pass, edges.begin(), edges.end(), costs.begin(),
                    static_cast<std::size_t>(rows) * cols);
  std::vector<Graph::vertex_descriptor> predecessor(num_vertices(graph));
  std::vector<double> distance(num_vertices(graph));
  boost::dijkstra_shortest_paths(
      graph, static_cast<Graph::vertex_descriptor>(index(from.y, from.x)),
      boost::predecessor_map(boost::make_iterator_property_map(predecessor.begin(), get(boost::vertex_index, graph)))
          .distance_map(boost::make_iterator_property_map(distance.begin(), get(boost::vertex_index, graph)))
          .weight_map(get(&Edge::cost, graph)));
  // The goal's cell, or the reached cell nearest the goal (a goal tight beside an obstacle, where
  // the outline fits only along it): the last motion to the goal is checked like the others.
  const int target = NearestReached(map, distance, goal);
  if (target < 0) return {};
  std::vector<Eigen::Vector2d> cells;
  for (int v = target; v != index(from.y, from.x); v = static_cast<int>(predecessor[v])) {
    cells.push_back(map.CellCentre({v % cols, v / cols}));
    if (predecessor[v] == static_cast<Graph::vertex_descriptor>(v)) return {};  // not reached
  }
  std::reverse(cells.begin(), cells.end());
  return cells;
}

// RouteCells as the drive's motions: a vertex about every 0.4 m along the route, headed along its
// incoming motion, then the goal, each motion checked with the whole outline. Where the next
// vertex cannot be reached so (a narrow passage entered at an angle: a 0.7 m long base with 2 cm to
// spare a side fits only within 3 degrees of its axis), the route is pulled taut there instead:
// the farthest of its points within kPullReach that a motion reaches, which lines the base up
// with the passage. RRT* with a fixed number of iterations can settle on the wrong side of a row of
// bushes, which no shortcutting undoes, and rarely samples such a passage's narrow band of poses;
// this route is the other candidate, and the cheaper valid one is kept. Empty when some vertex
// reaches no point further on.
std::vector<Pose2> GridRoute(const GlobalPlanner& planner, const ClearanceRule& rule, const Pose2& start,
                             const Eigen::Vector2d& goal) {
  std::vector<Eigen::Vector2d> points = RouteCells(planner, rule, start, goal);
  if (points.empty()) return {};
  if ((points.back() - goal).norm() > 1e-9) points.push_back(goal);
  constexpr double kSpacing = 0.4;           // m between vertices where the motions are clear
  constexpr double kPullReach = 4.0;         // m along the route: bounds the motions tried from a vertex
  constexpr int kMotionBudget = 3000;        // motions checked in all before the route is given up
  std::vector<double> along(points.size());  // m along the route from the start
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector2d previous = k == 0 ? Eigen::Vector2d(start.x, start.y) : points[k - 1];
    along[k] = (k == 0 ? 0.0 : along[k - 1]) + (points[k] - previous).norm();
  }
  // The motion from `from` to route point k, moved `side` metres square to the motion (the cells'
  // centres lie up to half a cell off a passage's midline; a passage with 2 cm to spare needs better).
  const auto motion_to = [&](const Pose2& from, std::size_t k, double side) {
    const Eigen::Vector2d d = points[k] - Eigen::Vector2d(from.x, from.y);
    const Eigen::Vector2d to = points[k] + side * Eigen::Vector2d(-d.y(), d.x()).normalized();
    return Pose2{to.x(), to.y(), std::atan2(to.y() - from.y, to.x() - from.x)};
  };
  const double quarter = 0.25 * planner.map().resolution();
  const std::array<double, 5> sides{0.0, quarter, -quarter, 2.0 * quarter, -2.0 * quarter};
  // A depth-first search over the vertices: each tries its candidates in turn - the point 0.4 m
  // on, then the farthest points first at each sideways offset - and when none leads on, the
  // vertex before it tries its next (a vertex 0.4 m on can leave no room to turn into a passage).
  struct Vertex {
    Pose2 pose;
    double at = 0.0;        // m along the route
    std::size_t next = 0;   // first route point beyond it
    std::size_t tried = 0;  // candidates tried
  };
  std::vector<Vertex> path{{start, 0.0, 0, 0}};
  int budget = kMotionBudget;
  while (!path.empty() && path.back().next < points.size()) {
    Vertex& v = path.back();
    std::size_t spaced = v.next, farthest = v.next;
    while (spaced + 1 < points.size() && along[spaced] - v.at < kSpacing) ++spaced;
    while (farthest + 1 < points.size() && along[farthest + 1] - v.at <= kPullReach) ++farthest;
    const std::size_t per_side = farthest + 1 - v.next;
    std::optional<Vertex> found;
    for (; !found && v.tried < 1 + sides.size() * per_side && budget > 0; ++v.tried) {
      const std::size_t c = v.tried == 0 ? 0 : v.tried - 1;
      const std::size_t k = v.tried == 0 ? spaced : farthest - c % per_side;
      const double side = v.tried == 0 ? 0.0 : sides[c / per_side];
      if (k + 1 == points.size() && side != 0.0) continue;  // the goal stays where it is
      const Pose2 to = motion_to(v.pose, k, side);
      --budget;
      if (MotionClear(planner, rule, v.pose, to)) found = Vertex{to, along[k], k + 1, 0};
    }
    if (budget <= 0) return {};
    if (found) {
      path.push_back(*found);
    } else {
      path.pop_back();
    }
  }
  std::vector<Pose2> poses;
  for (const Vertex& v : path) poses.push_back(v.pose);
  return poses;
}

}  // namespace

std::optional<double> GlobalPlanner::FreeHeading(const Eigen::Vector2d& position) const {
  const auto [yaw, clearance] = BestHeading(*this, position);
  if (clearance < parameters_.min_clearance) return std::nullopt;
  return yaw;
}

std::vector<Eigen::Vector2d> GlobalPlanner::StandablePositions(const Eigen::Vector2d& point, double radius, int count,
                                                               std::optional<double> yaw) const {
  std::vector<Eigen::Vector2d> positions;
  if (count <= 0) return positions;
  if (BestHeading(*this, point, yaw).second >= parameters_.min_clearance && Enterable(*this, point, yaw)) {
    positions.push_back(point);
  }
  const double step = map_.resolution();
  for (double r = step; r <= radius + 1e-9 && static_cast<int>(positions.size()) < count; r += step) {
    // Within a ring, the roomiest first: where the outline has more clearance it can also turn.
    std::vector<std::pair<double, Eigen::Vector2d>> ring;
    const int around = std::max(8, static_cast<int>(std::ceil(2.0 * M_PI * r / step)));
    for (int k = 0; k < around; ++k) {
      const double a = 2.0 * M_PI * k / around;
      const Eigen::Vector2d candidate = point + r * Eigen::Vector2d(std::cos(a), std::sin(a));
      const double clearance = BestHeading(*this, candidate, yaw).second;
      if (clearance >= parameters_.min_clearance) ring.emplace_back(clearance, candidate);
    }
    std::stable_sort(ring.begin(), ring.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    for (const auto& [clearance, candidate] : ring) {
      if (static_cast<int>(positions.size()) < count && Enterable(*this, candidate, yaw)) {
        positions.push_back(candidate);
      }
    }
  }
  return positions;
}

double GlobalPlanner::MotionCost(const Pose2& a, const Pose2& b) const {
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  if (length < 1e-9) return parameters_.turn_cost * std::abs(OmplYaw(b.yaw - a.yaw));
  const double heading = std::atan2(b.y - a.y, b.x - a.x);
  double cost =
      length + parameters_.turn_cost * (std::abs(OmplYaw(heading - a.yaw)) + std::abs(OmplYaw(b.yaw - heading)));
  // Clearance below the preferred costs extra, sampled at the middles of 0.2 m pieces. For speed
  // (RRT* costs every candidate edge: this is most of its time) the clearance here is the distance
  // from the outline's centre to the nearest occupied cell less its half width - exact beside a
  // wall, more than the outline's own clearance ahead and behind. The walls are checked exactly.
  const double preferred = parameters_.preferred_clearance;
  if (parameters_.clearance_cost <= 0.0 || preferred <= 0.0) return cost;
  const double half_width = 0.5 * outline_.width();
  const double centre_x = 0.5 * (outline_.min().x() + outline_.max().x());
  const int pieces = std::max(1, static_cast<int>(std::ceil(length / 0.2)));
  const Eigen::Vector2d centre_offset = centre_x * Eigen::Vector2d(std::cos(heading), std::sin(heading));
  for (int k = 0; k < pieces; ++k) {
    const double f = (k + 0.5) / pieces;
    const Eigen::Vector2d centre = Eigen::Vector2d(a.x + f * (b.x - a.x), a.y + f * (b.y - a.y)) + centre_offset;
    const double clearance = map_.DistanceToObstacleAtCell(centre) - half_width;
    cost += length / pieces * parameters_.clearance_cost * std::max(0.0, 1.0 - clearance / preferred);
  }
  return cost;
}

namespace {

// The approach poses of the goal pose `at`: a base length behind it, from which the robot drives
// straight in, and the first pose further back, up to 4 m, where the base can turn all the way
// round (a goal beside a wall is reached by a run along the wall: TurnableApproach). A pose tight
// between obstacles can otherwise be entered only from a tree node in the narrow cone in line with
// it; an approach pose is entered from any node that can turn there.
std::vector<Pose2> ApproachPoses(const GlobalPlanner& planner, const ClearanceRule& rule, const Pose2& at) {
  std::vector<Pose2> approaches;
  const double length = planner.outline().length();
  const Pose2 behind{at.x - length * std::cos(at.yaw), at.y - length * std::sin(at.yaw), at.yaw};
  if (planner.Valid(behind) && MotionClear(planner, rule, behind, at)) approaches.push_back(behind);
  if (const auto turnable = TurnableApproach(planner, rule, at, kMaxApproachRun);
      turnable && std::hypot(turnable->x - at.x, turnable->y - at.y) > length) {
    approaches.push_back(*turnable);
  }
  return approaches;
}

// An RRT* search and what its path is simplified with.
struct RrtStarSearch {
  ob::SpaceInformationPtr si;
  ob::ProblemDefinitionPtr problem;
  ob::OptimizationObjectivePtr objective;
  bool exact = false;  // found a path to a goal state
};

// RRT* in SE(2) from `start` to one of `goal_states` (the goal at each heading that fits, each
// followed by its approach poses); `message` says why when it found no exact solution.
RrtStarSearch SolveRrtStar(const GlobalPlanner& planner, const ClearanceRule& rule, const Pose2& start,
                           const std::vector<Pose2>& goal_states, double tolerance, int attempt, std::string* message) {
  const OccupancyGrid& map = planner.map();
  auto space = std::make_shared<ob::SE2StateSpace>();
  ob::RealVectorBounds bounds(2);
  bounds.setLow(0, map.origin().x());
  bounds.setLow(1, map.origin().y());
  bounds.setHigh(0, map.origin().x() + map.size().x());
  bounds.setHigh(1, map.origin().y() + map.size().y());
  space->setBounds(bounds);
  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([&planner, &rule](const ob::State* state) {
    const Pose2 p = ToPose(state);
    const double wanted = rule.At({p.x, p.y});
    return planner.Clearance(p, wanted) >= wanted;
  });
  si->setMotionValidator(std::make_shared<DriveMotionValidator>(si, planner, rule));
  si->setup();
  ob::ScopedState<ob::SE2StateSpace> state(space);
  SetPose(start, state.get());
  auto problem = std::make_shared<ob::ProblemDefinition>(si);
  problem->addStartState(state);
  auto goals = std::make_shared<ob::GoalStates>(si);
  goals->setThreshold(tolerance);
  for (const Pose2& pose : goal_states) {
    SetPose(pose, state.get());
    goals->addState(state);
  }
  problem->setGoal(goals);
  auto objective = std::make_shared<DriveObjective>(si, planner);
  problem->setOptimizationObjective(objective);
  auto rrt = std::make_shared<og::RRTstar>(si);
  rrt->setRange(planner.parameters().range);
  rrt->setKNearest(false);  // neighbours within the shrinking RRT* radius: fewer long edges to cost
  rrt->setProblemDefinition(problem);
  rrt->setup();
  ob::IterationTerminationCondition budget(static_cast<unsigned>(planner.parameters().iterations)
                                           << std::clamp(attempt, 0, 4));
  const ob::PlannerStatus status = rrt->solve(budget);
  if (status != ob::PlannerStatus::EXACT_SOLUTION) {
    *message = std::string("no path found (") + status.asString() + ", " +
               std::to_string(problem->getSolutionDifference()) + " m short)";
  }
  return {si, problem, objective, status == ob::PlannerStatus::EXACT_SOLUTION};
}

// The search's path, simplified and shortcut; ending on one of `approaches` it drives straight in
// to `goal`. Empty without an exact solution.
std::vector<Pose2> SimplifiedPath(const GlobalPlanner& planner, const ClearanceRule& rule, const RrtStarSearch& search,
                                  const Eigen::Vector2d& goal, const std::vector<Pose2>& approaches, double tolerance) {
  if (!search.exact) return {};
  auto& path = *search.problem->getSolutionPath()->as<og::PathGeometric>();
  // Only simplifications that join existing vertices: OMPL's shortcutting also joins points
  // interpolated within a motion, assuming a part of a valid motion is valid - not so for
  // turn-drive-turn motions (the interpolated pose's heading makes its own turn).
  og::PathSimplifier simplifier(search.si, search.problem->getGoal(), search.objective);
  for (bool changed = true; changed;) {
    changed = simplifier.reduceVertices(path);
    changed = simplifier.collapseCloseVertices(path) || changed;
  }
  std::vector<Pose2> poses;
  for (const ob::State* s : path.getStates()) poses.push_back(ToPose(s));
  for (const Pose2& approach : approaches) {  // ended on an approach pose: drive straight in
    if (std::hypot(poses.back().x - approach.x, poses.back().y - approach.y) <= tolerance + 1e-9) {
      poses.push_back({goal.x(), goal.y(), approach.yaw});
      break;
    }
  }
  Shortcut(planner, rule, &poses);
  return poses;
}

// The grid route straight to the goal; where its last motion cannot arrive (no heading it comes
// in at fits there), to an approach pose and straight in from it. Empty when there is none.
std::vector<Pose2> GridRouteToGoal(const GlobalPlanner& planner, const ClearanceRule& rule, const Pose2& start,
                                   const Eigen::Vector2d& goal, const std::vector<Pose2>& approaches) {
  std::vector<Pose2> route = GridRoute(planner, rule, start, goal);
  for (std::size_t a = 0; route.empty() && a < approaches.size(); ++a) {
    route = GridRoute(planner, rule, start, {approaches[a].x, approaches[a].y});
    const Pose2 in{goal.x(), goal.y(), approaches[a].yaw};
    if (!route.empty() && MotionClear(planner, rule, route.back(), in)) {
      route.push_back(in);
    } else {
      route.clear();
    }
  }
  if (!route.empty()) Shortcut(planner, rule, &route);
  return route;
}

// The outline's smallest clearance driving straight from `from` to `to` (sampled every half cell),
// at most preferred_clearance.
double SegmentClearance(const GlobalPlanner& planner, const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  const double enough = planner.parameters().preferred_clearance;
  const double length = (to - from).norm();
  const double heading = length > 1e-9 ? std::atan2(to.y() - from.y(), to.x() - from.x()) : 0.0;
  const int steps = std::max(1, static_cast<int>(std::ceil(length / (0.5 * planner.map().resolution()))));
  double smallest = enough;
  for (int k = 0; k <= steps; ++k) {
    const Eigen::Vector2d q = from + (static_cast<double>(k) / steps) * (to - from);
    smallest = std::min(smallest, planner.Clearance({q.x(), q.y(), heading}, enough));
  }
  return smallest;
}

// The follower turns at each vertex from the incoming to the outgoing direction; the motions
// checked turned through the vertex's own heading. Give the vertices their arrival headings and
// keep that if it is still clear (it nearly always is).
std::vector<Pose2> WithArrivalHeadings(const GlobalPlanner& planner, const ClearanceRule& rule,
                                       const std::vector<Pose2>& poses) {
  std::vector<Pose2> arriving = poses;
  for (std::size_t i = 1; i < arriving.size(); ++i) {
    const Pose2& p = arriving[i - 1];
    if (std::hypot(arriving[i].x - p.x, arriving[i].y - p.y) > 1e-9) {
      arriving[i].yaw = std::atan2(arriving[i].y - p.y, arriving[i].x - p.x);
    }
  }
  for (std::size_t i = 1; i < arriving.size(); ++i) {
    if (!MotionClear(planner, rule, arriving[i - 1], arriving[i])) return poses;
  }
  return arriving;
}

}  // namespace

PlanResult GlobalPlanner::Plan(const Pose2& start, const Eigen::Vector2d& goal, double tolerance, int attempt,
                               std::optional<double> yaw) const {
  PlanResult result;
  std::vector<double> goal_headings;
  for (const double heading : GoalHeadings(yaw)) {
    if (Valid({goal.x(), goal.y(), heading})) goal_headings.push_back(heading);
  }
  if (goal_headings.empty()) {
    result.message = "the outline keeps " + std::to_string(parameters_.min_clearance) + " m from the obstacles at " +
                     (yaw ? "the goal's heading" : "no heading") + " at the goal";
    return result;
  }
  // After a drift or a recovery the robot may believe its outline overlaps an obstacle: plan from
  // the nearest pose that fits and go there first.
  Pose2 planning_start = start;
  if (Clearance(start, 0.0) < 0.0) {
    const std::vector<Eigen::Vector2d> free =
        StandablePositions({start.x, start.y}, parameters_.start_escape_radius, 1);
    if (free.empty()) {
      result.message = "the start overlaps an obstacle of the map and no pose within " +
                       std::to_string(parameters_.start_escape_radius) + " m fits";
      return result;
    }
    planning_start = {free.front().x(), free.front().y(), *FreeHeading(free.front())};
  }
  const ClearanceRule rule(*this, planning_start);
  std::vector<Pose2> goal_states, approaches;
  for (const double yaw : goal_headings) {
    goal_states.push_back({goal.x(), goal.y(), yaw});
    const std::vector<Pose2> more = ApproachPoses(*this, rule, goal_states.back());
    goal_states.insert(goal_states.end(), more.begin(), more.end());
    approaches.insert(approaches.end(), more.begin(), more.end());
  }
  // Two candidates, the cheaper valid one kept: RRT* and the grid route (GridRoute says why). In
  // this order: both draw from OMPL's seeded generators, so the order fixes the plans.
  const RrtStarSearch search =
      SolveRrtStar(*this, rule, planning_start, goal_states, tolerance, attempt, &result.message);
  const std::vector<Pose2> route = GridRouteToGoal(*this, rule, planning_start, goal, approaches);
  std::vector<Pose2> poses = SimplifiedPath(*this, rule, search, goal, approaches, tolerance);
  if (poses.empty() || (!route.empty() && PathCost(*this, route) < PathCost(*this, poses))) poses = route;
  if (poses.empty()) return result;
  result.message.clear();
  poses = WithArrivalHeadings(*this, rule, poses);
  if (yaw) {
    // The turn on the spot to the goal's heading where the path ends (the follower makes it).
    const Pose2 facing{poses.back().x, poses.back().y, OmplYaw(*yaw)};
    if (!MotionClear(*this, rule, poses.back(), facing)) {
      result.message = "no room to turn to the goal's heading where the path ends";
      return result;
    }
    poses.push_back(facing);
  }

  if (planning_start.x != start.x || planning_start.y != start.y) result.path.push_back({start.x, start.y});
  for (const Pose2& p : poses) {
    const Eigen::Vector2d point(p.x, p.y);
    if (result.path.empty() || (point - result.path.back()).norm() > 1e-9) result.path.push_back(point);
  }
  if (result.path.size() < 2) result.path.push_back(result.path.back());
  for (std::size_t i = 1; i < result.path.size(); ++i) {
    result.length += (result.path[i] - result.path[i - 1]).norm();
    result.clearance.push_back(SegmentClearance(*this, result.path[i - 1], result.path[i]));
  }
  result.cost = PathCost(*this, poses);
  result.found = true;
  return result;
}

}  // namespace trimbot::stack
