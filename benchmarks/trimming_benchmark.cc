// Trimming's planning times (issue 31): the GTSP solvers on instances of the cutting path's size,
// and the full cutting path over a ball in front of the robot (blade poses, inverse kinematics of
// every pose and roll, joint move times, the search and its lazy collision checks), and the plan
// adapted from a stored path (issue 31's target: <= 100 ms per bush) beside it. Both with the
// stack's own trim settings (robot/config/stack.yaml: pose spacing, rolls, the search's restarts,
// the arm's clearance from the robot's body, the blade's depth), as `trimbot trim precompute`
// solves and the trim executive adapts.
#include <benchmark/benchmark.h>

#include <cmath>

#include "trimbot/common/random.h"
#include "trimbot/robot/collision_model.h"
#include "trimbot/robot/robot_parameters.h"
#include "trimbot/stack/stack_parameters.h"
#include "trimbot/trimming/cutting_path.h"
#include "trimbot/trimming/plan_database.h"

namespace {

using namespace trimbot;

// m clusters of k points each, uniform in the unit square, Euclidean costs.
trimming::GtspInstance RandomInstance(int m, int k) {
  Rng rng = MakeRng(7, "trimming_benchmark");
  std::vector<Eigen::Vector2d> points;
  trimming::GtspInstance instance;
  instance.clusters.resize(static_cast<std::size_t>(m));
  for (int i = 0; i < m * k; ++i) {
    instance.clusters[static_cast<std::size_t>(i % m)].push_back(i);
    const double x = UniformUnit(rng);
    points.emplace_back(x, UniformUnit(rng));
  }
  const auto n = static_cast<Eigen::Index>(points.size());
  instance.cost.resize(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j)
      instance.cost(i, j) = (points[static_cast<std::size_t>(i)] - points[static_cast<std::size_t>(j)]).norm();
  }
  return instance;
}

void BM_GtspExact12(benchmark::State& state) {
  const trimming::GtspInstance instance = RandomInstance(12, 5);
  for (auto _ : state) benchmark::DoNotOptimize(trimming::SolveGtspExact(instance).cost);
}
BENCHMARK(BM_GtspExact12)->Unit(benchmark::kMillisecond);

// Clusters x nodes per cluster: the cutting path has about 20-40 reachable poses of 10-25 solutions.
void BM_GtspSearch(benchmark::State& state) {
  const trimming::GtspInstance instance =
      RandomInstance(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  double cost = 0.0, greedy = trimming::SolveGtspNearestNeighbour(instance).cost;
  for (auto _ : state) cost = trimming::SolveGtspLargeNeighbourhood(instance).cost;
  state.counters["cost_over_nearest_neighbour"] = cost / greedy;
}
BENCHMARK(BM_GtspSearch)->Args({12, 5})->Args({30, 12})->Args({40, 20})->Unit(benchmark::kMillisecond);

// The robot's arm with its collision model, and a 0.6 m ball 0.95 m ahead.
struct BallInFront {
  robot::RobotDescription robot = robot::RobotDescription::Load(TRIMBOT_SOURCE_DIR "/robot/urdf/trimbot.urdf");
  trimming::TrimParameters trim = stack::StackParameters::Load(TRIMBOT_SOURCE_DIR "/robot/config/stack.yaml").Trim();
  trimming::CuttingPathOptions path = trim.PathOptions();  // the planner's speeds and inverse kinematics
  arm::ArmKinematics kinematics{robot};
  robot::CollisionModel collision{robot, robot.ArmJointNames(), trim.planner.body_clearance};
  Eigen::VectorXd home;
  Eigen::Isometry3d T_cutter_blade = robot.BladeInCutter();
  perception::TopiaryShape target;

  BallInFront() {
    const auto p = robot::RobotParameters::Load(TRIMBOT_SOURCE_DIR "/robot/config/robot_parameters.yaml");
    home = Eigen::Map<const Eigen::VectorXd>(p.arm_home_position.data(), 6);
    target.centre = {0.95, 0.0, 0.35};
    target.half = Eigen::Vector3d::Constant(0.3);
    kinematics.PrepareDatabase(path.ik);
  }
  // The checks for a blade aimed `depth` inside `shape`, as the trim executive makes them.
  trimming::CuttingChecks Checks(const perception::TopiaryShape& shape, double depth) {
    return trimming::MakeCuttingChecks(kinematics, T_cutter_blade, &collision, shape,
                                       trimming::CheckDepth(shape, depth, trim.poses.spacing, robot.BladeThickness()),
                                       trim.planner);
  }
  // The blade on the target, the search as the stack runs it online (trimbot trim precompute runs
  // GLNS's slower default mode).
  trimming::CuttingPath PlanInFull() {
    const trimming::CuttingChecks checks = Checks(target, 0.0);
    return trimming::PlanCuttingPath(kinematics, T_cutter_blade, home, trimming::CuttingPoses(target, trim.poses),
                                     checks.valid, checks.free_move, path);
  }
};

void BM_CuttingPathOverABall(benchmark::State& state) {
  BallInFront ball;
  trimming::CuttingPath path;
  for (auto _ : state) path = ball.PlanInFull();
  state.counters["poses"] = static_cast<double>(trimming::CuttingPoses(ball.target, ball.trim.poses).size());
  state.counters["reachable"] = path.clusters;
  state.counters["tour_s"] = path.motion_time;
  state.counters["nearest_neighbour_s"] = path.nearest_neighbour_time;
  state.counters["refused_moves"] = path.refused_moves;
}
BENCHMARK(BM_CuttingPathOverABall)->Unit(benchmark::kSecond)->Iterations(1);

// The plan from a stored path (issue 31's target: <= 100 ms per bush): the path over the ball,
// planned once, adapted to balls 2-5 cm off and up to 3 cm larger or smaller.
void BM_AdaptStoredPath(benchmark::State& state) {
  BallInFront ball;
  const trimming::CuttingPath full = ball.PlanInFull();
  const trimming::StoredCuttingPath stored = trimming::ToStored(full, ball.target);
  Rng rng = MakeRng(11, "adapt_benchmark");
  double kept = 0.0, time_ratio = 0.0;
  int adaptations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    perception::TopiaryShape moved = ball.target;
    const double angle = 2.0 * M_PI * UniformUnit(rng), offset = 0.02 + 0.03 * UniformUnit(rng);
    moved.centre += offset * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
    moved.half = Eigen::Vector3d::Constant(0.27 + 0.06 * UniformUnit(rng));
    const trimming::CuttingChecks checks = ball.Checks(moved, ball.trim.blade_depth);
    // The blade aimed blade_depth inside the fit all over (leaves seen everywhere).
    const trimming::BladeSurface surface(moved, ball.trim.blade_depth, [](const Eigen::Vector3d&) { return true; });
    state.ResumeTiming();
    const trimming::CuttingPath adapted = trimming::AdaptCuttingPath(
        ball.kinematics, ball.T_cutter_blade, ball.home, stored, surface, checks.valid, checks.free_move, ball.path);
    kept += static_cast<double>(adapted.poses.size()) / static_cast<double>(full.poses.size());
    time_ratio += adapted.ok ? adapted.motion_time / full.motion_time : 0.0;
    ++adaptations;
  }
  state.counters["poses_kept_share"] = kept / adaptations;
  state.counters["motion_time_over_full_plan"] = time_ratio / adaptations;
  state.counters["full_plan_poses"] = static_cast<double>(full.poses.size());
}
BENCHMARK(BM_AdaptStoredPath)->Unit(benchmark::kMillisecond)->Iterations(20);

}  // namespace

BENCHMARK_MAIN();
