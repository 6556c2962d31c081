#include "trimbot/arm/arm_planner.h"

#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SO2StateSpace.h>
#include <ompl/base/terminationconditions/IterationTerminationCondition.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/planners/prm/LazyPRM.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "trimbot/common/pose2.h"

namespace trimbot::arm {

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

// Joint-space length of a path.
double Length(const std::vector<Eigen::VectorXd>& path) {
  double length = 0.0;
  for (size_t k = 1; k < path.size(); ++k) length += (path[k] - path[k - 1]).norm();
  return length;
}

// A piece of path moved along without stopping: one trapezoidal speed profile over its arc length.
struct Piece {
  std::vector<Eigen::VectorXd> points;
  std::vector<double> arc;  // cumulative length at each point
  double speed = 0.0, acceleration = 0.0, ramp_time = 0.0, cruise_time = 0.0, duration = 0.0;

  Piece(std::vector<Eigen::VectorXd> path, const Eigen::VectorXd& velocity_limits, double joint_acceleration)
      : points(std::move(path)) {
    arc.push_back(0.0);
    speed = std::numeric_limits<double>::infinity();
    acceleration = std::numeric_limits<double>::infinity();
    for (size_t k = 1; k < points.size(); ++k) {
      const Eigen::VectorXd step = points[k] - points[k - 1];
      const double length = step.norm();
      arc.push_back(arc.back() + length);
      if (length < 1e-12) continue;
      const Eigen::VectorXd unit = step.cwiseAbs() / length;  // joint rate per unit of arc length
      for (int i = 0; i < unit.size(); ++i) {
        if (unit(i) < 1e-12) continue;
        speed = std::min(speed, velocity_limits(i) / unit(i));
        acceleration = std::min(acceleration, joint_acceleration / unit(i));
      }
    }
    const double length = arc.back();
    if (length < 1e-12) return;
    // Trapezoid, or a triangle when the piece is too short to reach the speed.
    if (speed * speed / acceleration > length) speed = std::sqrt(length * acceleration);
    ramp_time = speed / acceleration;
    cruise_time = (length - speed * ramp_time) / speed;
    duration = 2.0 * ramp_time + cruise_time;
  }

  // Arc length and its rate at time t of the piece.
  std::pair<double, double> At(double t) const {
    const double length = arc.back();
    if (duration <= 0.0) return {length, 0.0};
    t = std::clamp(t, 0.0, duration);
    if (t < ramp_time) return {0.5 * acceleration * t * t, acceleration * t};
    if (t < ramp_time + cruise_time) return {0.5 * speed * ramp_time + speed * (t - ramp_time), speed};
    const double left = duration - t;
    return {length - 0.5 * acceleration * left * left, acceleration * left};
  }

  void Sample(double t, Eigen::VectorXd* position, Eigen::VectorXd* velocity) const {
    const auto [s, rate] = At(t);
    const size_t k = std::min<size_t>(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin(), points.size() - 1);
    const size_t a = k == 0 ? 0 : k - 1;
    const double span = arc[k] - arc[a];
    const double u = span > 1e-12 ? (s - arc[a]) / span : 1.0;
    *position = points[a] + u * (points[k] - points[a]);
    *velocity = span > 1e-12 ? Eigen::VectorXd((points[k] - points[a]) * (rate / span))
                             : Eigen::VectorXd::Zero(position->size());
  }
};

// Ends every path at the exact waypoint (time sampling would stop just short of it).
JointTrajectory Timed(const std::vector<Piece>& pieces, double sample_period) {
  JointTrajectory trajectory;
  double offset = 0.0;
  for (const Piece& piece : pieces) {
    const int samples = std::max(1, static_cast<int>(std::ceil(piece.duration / sample_period)));
    for (int n = trajectory.times.empty() ? 0 : 1; n <= samples; ++n) {
      const double t = piece.duration * n / samples;
      Eigen::VectorXd q, v;
      piece.Sample(t, &q, &v);
      trajectory.times.push_back(offset + t);
      trajectory.positions.push_back(q);
      trajectory.velocities.push_back(v);
    }
    offset += piece.duration;
  }
  return trajectory;
}

}  // namespace

void JointTrajectory::Sample(double t, Eigen::VectorXd* position, Eigen::VectorXd* velocity) const {
  if (times.empty()) return;
  if (t <= times.front() || times.size() == 1) {
    *position = positions.front();
    *velocity = velocities.front();
    return;
  }
  if (t >= times.back()) {
    *position = positions.back();
    *velocity = velocities.back();
    return;
  }
  const size_t k = std::upper_bound(times.begin(), times.end(), t) - times.begin();
  const double u = (t - times[k - 1]) / (times[k] - times[k - 1]);
  *position = positions[k - 1] + u * (positions[k] - positions[k - 1]);
  *velocity = velocities[k - 1] + u * (velocities[k] - velocities[k - 1]);
}

JointTrajectory TimeParameterize(const std::vector<Eigen::VectorXd>& waypoints, const Eigen::VectorXd& velocity_limits,
                                 double acceleration, const std::vector<bool>& stops, double sample_period) {
  if (!stops.empty() && stops.size() != waypoints.size())
    throw std::invalid_argument("TimeParameterize: one stop flag per waypoint");
  std::vector<Piece> pieces;
  std::vector<Eigen::VectorXd> stretch;
  for (size_t k = 0; k < waypoints.size(); ++k) {
    stretch.push_back(waypoints[k]);
    if (k > 0 && (stops.empty() || stops[k] || k + 1 == waypoints.size())) {
      pieces.emplace_back(stretch, velocity_limits, acceleration);
      stretch = {waypoints[k]};
    }
  }
  if (pieces.empty() && !waypoints.empty()) pieces.emplace_back(waypoints, velocity_limits, acceleration);
  return Timed(pieces, sample_period);
}

std::vector<Eigen::VectorXd> JointSteps(const Eigen::VectorXd& from, const Eigen::VectorXd& to, double step) {
  const Eigen::VectorXd d = to - from;
  const int steps = std::max(1, static_cast<int>(std::ceil(d.cwiseAbs().maxCoeff() / step)));
  std::vector<Eigen::VectorXd> states;
  for (int k = 1; k <= steps; ++k) states.push_back(from + d * (static_cast<double>(k) / steps));
  return states;
}

std::vector<Eigen::Isometry3d> PosesAlongLine(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double step) {
  const Eigen::AngleAxisd turn(from.linear().transpose() * to.linear());
  const double distance = (to.translation() - from.translation()).norm();
  constexpr double kRadiansPerMetre = 10.0;  // a 5 mm step turns at most 0.05 rad
  const int steps =
      std::max(1, static_cast<int>(std::ceil(std::max(distance, turn.angle() / kRadiansPerMetre) / step)));
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 1; k <= steps; ++k) {
    const double s = static_cast<double>(k) / steps;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = from.translation() + s * (to.translation() - from.translation());
    pose.linear() = from.linear() * Eigen::AngleAxisd(s * turn.angle(), turn.axis()).toRotationMatrix();
    poses.push_back(pose);
  }
  return poses;
}

// ---------------------------------------------------------------- OMPL

struct ArmPlanner::Ompl {
  std::shared_ptr<ob::CompoundStateSpace> space;
  ob::SpaceInformationPtr si;
  std::shared_ptr<og::LazyPRM> roadmap;  // kept between queries (ResetRoadmap drops it)
  std::vector<bool> continuous;
  long checks = 0;

  Eigen::VectorXd ToVector(const ob::State* state) const {
    const auto* compound = state->as<ob::CompoundState>();
    Eigen::VectorXd q(static_cast<int>(continuous.size()));
    for (size_t i = 0; i < continuous.size(); ++i) {
      q(static_cast<int>(i)) = continuous[i] ? compound->as<ob::SO2StateSpace::StateType>(i)->value
                                             : compound->as<ob::RealVectorStateSpace::StateType>(i)->values[0];
    }
    return q;
  }
  void FromVector(const Eigen::VectorXd& q, ob::State* state) const {
    auto* compound = state->as<ob::CompoundState>();
    for (size_t i = 0; i < continuous.size(); ++i) {
      if (continuous[i]) {
        compound->as<ob::SO2StateSpace::StateType>(i)->value = WrapAngle(q(static_cast<int>(i)));
      } else {
        compound->as<ob::RealVectorStateSpace::StateType>(i)->values[0] = q(static_cast<int>(i));
      }
    }
    space->enforceBounds(state);
  }
  ob::ScopedState<> Scoped(const Eigen::VectorXd& q) const {
    ob::ScopedState<> state(space);
    FromVector(q, state.get());
    return state;
  }
};

ArmPlanner::ArmPlanner(const ArmKinematics& kinematics, const robot::CollisionModel& collision,
                       const ArmPlannerParameters& parameters)
    : kinematics_(kinematics), collision_(collision), parameters_(parameters), ompl_(std::make_unique<Ompl>()) {
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  ompl_->space = std::make_shared<ob::CompoundStateSpace>();
  for (const JointLimit& limit : kinematics.limits()) {
    ompl_->continuous.push_back(limit.continuous);
    if (limit.continuous) {
      ompl_->space->addSubspace(std::make_shared<ob::SO2StateSpace>(), 1.0);
    } else {
      auto line = std::make_shared<ob::RealVectorStateSpace>(1);
      line->setBounds(limit.lower, limit.upper);
      ompl_->space->addSubspace(line, 1.0);
    }
  }
  ompl_->si = std::make_shared<ob::SpaceInformation>(ompl_->space);
  ompl_->si->setStateValidityChecker([this](const ob::State* state) {
    ++ompl_->checks;
    return Valid(ompl_->ToVector(state));
  });
  ompl_->si->setStateValidityCheckingResolution(parameters_.collision_step / ompl_->space->getMaximumExtent());
  ompl_->si->setup();
}

ArmPlanner::~ArmPlanner() = default;

bool ArmPlanner::Valid(const Eigen::VectorXd& q) const { return !collision_.Check(q).collision; }

void ArmPlanner::ResetRoadmap() { ompl_->roadmap.reset(); }

ArmPlan ArmPlanner::PlanToJoints(const Eigen::VectorXd& start, const Eigen::VectorXd& goal) {
  ArmPlan plan;
  plan.ik_solutions = 1;
  return Plan(start, {goal}, plan);
}

ArmPlan ArmPlanner::PlanToPose(const Eigen::VectorXd& start, const Eigen::Isometry3d& cutter) {
  const auto begin = std::chrono::steady_clock::now();
  const IkResult ik = kinematics_.InverseKinematics(cutter, parameters_.ik);
  ArmPlan plan;
  plan.ik_solutions = static_cast<int>(ik.solutions.size());
  if (ik.solutions.empty()) {
    plan.failure = "inverse kinematics: " + ik.failure;
  } else {
    plan = Plan(start, ik.solutions, plan);
  }
  plan.planning_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return plan;
}

ArmPlan ArmPlanner::Plan(const Eigen::VectorXd& start, const std::vector<Eigen::VectorXd>& goals, ArmPlan plan) {
  const auto begin = std::chrono::steady_clock::now();
  ompl_->checks = 0;
  const auto finish = [&](ArmPlan* result) {
    result->validity_checks = ompl_->checks;
    result->planning_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  };
  const robot::CollisionReport at_start = collision_.Check(start);
  if (at_start.collision) {
    plan.failure = "the start is in collision (" + at_start.pair.first + " - " + at_start.pair.second + ")";
    finish(&plan);
    return plan;
  }
  // The collision-free solutions, nearest to the start first (the joints' travel, the short way round).
  std::vector<std::pair<double, Eigen::VectorXd>> free;
  robot::CollisionReport blocked;
  for (const Eigen::VectorXd& q : goals) {
    const robot::CollisionReport report = collision_.Check(q);
    if (report.collision) {
      blocked = report;
      continue;
    }
    free.emplace_back(ompl_->space->distance(ompl_->Scoped(start).get(), ompl_->Scoped(q).get()), q);
  }
  plan.free_goals = static_cast<int>(free.size());
  if (free.empty()) {
    plan.failure = "all " + std::to_string(goals.size()) + " joint solutions collide (e.g. " + blocked.pair.first +
                   " - " + blocked.pair.second + ")";
    finish(&plan);
    return plan;
  }
  std::stable_sort(free.begin(), free.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  const ob::ScopedState<> from = ompl_->Scoped(start);
  // A straight joint-space motion to a solution, when one is free, is the shortest path there.
  for (const auto& [distance, q] : free) {
    if (!ompl_->si->checkMotion(from.get(), ompl_->Scoped(q).get())) continue;
    SetWaypoints(start, {q}, &plan);
    finish(&plan);
    return plan;
  }
  auto goal_states = std::make_shared<ob::GoalStates>(ompl_->si);
  for (const auto& [distance, q] : free) goal_states->addState(ompl_->Scoped(q));
  auto problem = std::make_shared<ob::ProblemDefinition>(ompl_->si);
  problem->addStartState(from);
  problem->setGoal(goal_states);

  ob::PlannerPtr planner;
  if (parameters_.algorithm == ArmPlannerParameters::Algorithm::kLazyPrm) {
    if (!ompl_->roadmap) ompl_->roadmap = std::make_shared<og::LazyPRM>(ompl_->si);
    ompl_->roadmap->clearQuery();  // keeps the roadmap
    planner = ompl_->roadmap;
  } else {
    planner = std::make_shared<og::RRTConnect>(ompl_->si);
  }
  planner->setProblemDefinition(problem);
  if (!planner->isSetup()) planner->setup();
  ob::IterationTerminationCondition budget(static_cast<unsigned>(parameters_.max_iterations));
  const ob::PlannerStatus status = planner->solve(budget);
  if (status != ob::PlannerStatus::EXACT_SOLUTION) {
    plan.failure = std::string("no collision-free path in ") + std::to_string(parameters_.max_iterations) +
                   " iterations (" + status.asString() + ")";
    finish(&plan);
    return plan;
  }
  og::PathGeometric path = *problem->getSolutionPath()->as<og::PathGeometric>();
  og::PathSimplifier simplifier(ompl_->si);
  simplifier.reduceVertices(path);
  simplifier.shortcutPath(path);
  std::vector<Eigen::VectorXd> states;
  for (size_t k = 1; k < path.getStateCount(); ++k) states.push_back(ompl_->ToVector(path.getState(k)));
  SetWaypoints(start, states, &plan);
  finish(&plan);
  return plan;
}

void ArmPlanner::SetWaypoints(const Eigen::VectorXd& start, const std::vector<Eigen::VectorXd>& states,
                              ArmPlan* plan) const {
  // Unwrapped from the start's own joint values, each continuous joint the short way round.
  plan->waypoints = {start};
  for (const Eigen::VectorXd& raw : states) {
    Eigen::VectorXd q = raw;
    for (int i = 0; i < q.size(); ++i) {
      if (ompl_->continuous[static_cast<size_t>(i)])
        q(i) = plan->waypoints.back()(i) + WrapAngle(raw(i) - plan->waypoints.back()(i));
    }
    plan->waypoints.push_back(q);
  }
  plan->trajectory = TimeParameterize(plan->waypoints, VelocityLimits(), parameters_.acceleration);
  Finish(plan);
}

Eigen::VectorXd ArmPlanner::VelocityLimits() const {
  Eigen::VectorXd limits(kinematics_.joints());
  for (int i = 0; i < kinematics_.joints(); ++i) {
    limits(i) = parameters_.velocity_scale * kinematics_.limits()[static_cast<size_t>(i)].velocity;
  }
  return limits;
}

void ArmPlanner::Finish(ArmPlan* plan) const {
  plan->ok = true;
  plan->path_length = Length(plan->waypoints);
  plan->cutter_path_length = 0.0;
  Eigen::Vector3d previous = kinematics_.EndEffectorPose(plan->trajectory.positions.front()).translation();
  for (const Eigen::VectorXd& q : plan->trajectory.positions) {
    const Eigen::Vector3d p = kinematics_.EndEffectorPose(q).translation();
    plan->cutter_path_length += (p - previous).norm();
    previous = p;
  }
}

std::optional<Eigen::VectorXd> ArmPlanner::NearestSolution(const Eigen::Isometry3d& pose, const Eigen::VectorXd& near,
                                                           std::string* failure) const {
  const IkResult ik = kinematics_.InverseKinematics(pose, parameters_.ik);
  std::optional<Eigen::VectorXd> best;
  for (const Eigen::VectorXd& solution : ik.solutions) {
    Eigen::VectorXd q = solution;
    for (int i = 0; i < q.size(); ++i) {
      if (kinematics_.limits()[static_cast<size_t>(i)].continuous) q(i) = near(i) + WrapAngle(q(i) - near(i));
    }
    if (!best || (q - near).cwiseAbs().maxCoeff() < (*best - near).cwiseAbs().maxCoeff()) best = q;
  }
  if (!best) *failure = ik.failure;
  return best;
}

ArmPlan ArmPlanner::CartesianPass(const Eigen::VectorXd& start, const Eigen::Isometry3d& to) {
  const auto begin = std::chrono::steady_clock::now();
  ArmPlan plan;
  const std::vector<Eigen::Isometry3d> line =
      PosesAlongLine(kinematics_.EndEffectorPose(start), to, parameters_.cartesian_step);
  plan.waypoints.push_back(start);
  for (std::size_t k = 0; k < line.size(); ++k) {
    const Eigen::Isometry3d& pose = line[k];
    const double s = static_cast<double>(k + 1) / line.size();
    const Eigen::VectorXd& previous = plan.waypoints.back();
    std::optional<Eigen::VectorXd> q = kinematics_.InverseKinematicsNear(pose, previous, parameters_.ik);
    std::string lost;
    if (!q) q = NearestSolution(pose, previous, &lost);  // LM from the last step can stall near a singularity
    std::ostringstream at;
    at << " at " << std::round(100.0 * s) << "% of the pass";
    if (!q) {
      plan.failure = "inverse kinematics lost the line" + at.str() + ": " + lost;
    } else if ((*q - previous).cwiseAbs().maxCoeff() > parameters_.cartesian_max_joint_step) {
      plan.failure = "the arm would switch branch" + at.str();
    } else {
      for (const Eigen::VectorXd& state : JointSteps(previous, *q, parameters_.collision_step)) {
        const robot::CollisionReport report = collision_.Check(state);
        ++plan.validity_checks;
        if (report.collision) {
          plan.failure = "collision (" + report.pair.first + " - " + report.pair.second + ")" + at.str();
          break;
        }
      }
    }
    if (!plan.failure.empty()) break;
    plan.waypoints.push_back(*q);
  }
  if (plan.failure.empty()) {
    // One speed profile over the whole line: the cutter does not stop at every step.
    plan.trajectory = Timed({Piece(plan.waypoints, VelocityLimits(), parameters_.acceleration)}, 0.02);
    Finish(&plan);
  } else {
    plan.waypoints.clear();
  }
  plan.planning_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return plan;
}

}  // namespace trimbot::arm
