// Arm planning time around a bush (issue target: median <= 50 ms), with the environment as the
// stack perceives it: the near half of a topiary's surface as noisy stereo points, turned into the
// planner's octree by the stack's own BuildPerceivedEnvironment, and the ground. Each query plans
// from where the last one ended to the next of 60 cutter poses around the bush (a trimming
// sequence), inverse kinematics included. Counters: median_ms, p90_ms, success rate, and the
// time of inverse kinematics alone.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "trimbot/arm/arm_executive.h"
#include "trimbot/common/random.h"
#include "trimbot/robot/robot_parameters.h"

namespace {

using namespace trimbot;

const Eigen::Vector3d kBushCentre(1.33, 0.0, 0.375);  // 0.7 m from the arm's axis to the outline
const Eigen::Vector3d kBushRadii(0.4, 0.4, 0.375);

struct Setup {
  robot::RobotDescription robot = robot::RobotDescription::Load(TRIMBOT_SOURCE_DIR "/robot/urdf/trimbot.urdf");
  arm::ArmExecutiveParameters parameters;
  arm::ArmKinematics kinematics{robot};
  robot::CollisionModel collision{robot, robot.ArmJointNames()};
  Eigen::VectorXd home;
  std::vector<Eigen::Isometry3d> goals;

  Setup() {
    const auto p = robot::RobotParameters::Load(TRIMBOT_SOURCE_DIR "/robot/config/robot_parameters.yaml");
    home = Eigen::Map<const Eigen::VectorXd>(p.arm_home_position.data(), 6);
    Rng rng(3);
    const auto uniform = [&rng]() { return UniformUnit(rng); };
    // What stereo sees of the bush: the half facing the robot, 1 cm apart, with 1 cm of noise.
    std::vector<Eigen::Vector3d> points;
    for (double el = -1.2; el <= 1.4; el += 0.025) {
      for (double az = M_PI / 2; az <= 3 * M_PI / 2; az += 0.025) {
        const Eigen::Vector3d unit(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
        const double u1 = uniform(), u2 = uniform(), u3 = uniform();  // drawn in order
        const double noise = 0.01 * (u1 + u2 + u3 - 1.5) * 2.0;
        points.push_back(kBushCentre + kBushRadii.cwiseProduct(unit) + noise * unit);
      }
    }
    arm::BuildPerceivedEnvironment(robot, parameters, points, {}, &collision.environment());
    // Cutter poses 5-25 cm outside the bush, reachable by a configuration the planner accepts.
    const arm::ArmPlanner check(kinematics, collision, parameters.planner);
    while (goals.size() < 60) {
      Eigen::VectorXd q(6);
      for (int i = 0; i < 6; ++i) {
        const arm::JointLimit& limit = kinematics.limits()[static_cast<size_t>(i)];
        q(i) = limit.continuous ? -M_PI + 2 * M_PI * uniform() : limit.lower + (limit.upper - limit.lower) * uniform();
      }
      const Eigen::Isometry3d cutter = kinematics.EndEffectorPose(q);
      const double radius = (cutter.translation() - kBushCentre).cwiseQuotient(kBushRadii).norm();
      if (radius < 1.15 || radius > 1.6 || !check.Valid(q)) continue;
      goals.push_back(cutter);
    }
    kinematics.PrepareDatabase(parameters.planner.ik);
  }
};

Setup& Shared() {
  static Setup setup;
  return setup;
}

double Percentile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(q * (values.size() - 1))];
}

void BM_PlanAroundABush(benchmark::State& state, arm::ArmPlannerParameters::Algorithm algorithm) {
  Setup& s = Shared();
  arm::ArmPlannerParameters parameters = s.parameters.planner;
  parameters.algorithm = algorithm;
  arm::ArmPlanner planner(s.kinematics, s.collision, parameters);
  std::vector<double> seconds;
  int succeeded = 0;
  size_t next = 0;
  Eigen::VectorXd at = s.home;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const arm::ArmPlan plan = planner.PlanToPose(at, s.goals[next++ % s.goals.size()]);
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (plan.ok) {
      ++succeeded;
      at = plan.trajectory.positions.back();
    }
  }
  state.counters["median_ms"] = 1e3 * Percentile(seconds, 0.5);
  state.counters["p90_ms"] = 1e3 * Percentile(seconds, 0.9);
  state.counters["success"] = static_cast<double>(succeeded) / static_cast<double>(seconds.size());
}
BENCHMARK_CAPTURE(BM_PlanAroundABush, rrt_connect, arm::ArmPlannerParameters::Algorithm::kRrtConnect)
    ->Iterations(60)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PlanAroundABush, lazy_prm, arm::ArmPlannerParameters::Algorithm::kLazyPrm)
    ->Iterations(60)
    ->Unit(benchmark::kMillisecond);

void BM_InverseKinematics(benchmark::State& state) {
  Setup& s = Shared();
  size_t next = 0;
  double solutions = 0.0;
  for (auto _ : state) {
    const arm::IkResult result =
        s.kinematics.InverseKinematics(s.goals[next++ % s.goals.size()], s.parameters.planner.ik);
    solutions += static_cast<double>(result.solutions.size());
  }
  state.counters["solutions"] = solutions / static_cast<double>(state.iterations());
}
BENCHMARK(BM_InverseKinematics)->Iterations(60)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
