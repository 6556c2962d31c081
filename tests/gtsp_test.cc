// The cutting path's combinatorial core: the GTSP solvers against instances with a known optimum,
// against each other on random instances, and on malformed input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "trimbot/common/random.h"
#include "trimbot/trimming/gtsp.h"

namespace trimbot::trimming {
namespace {

// Euclidean costs between planar points.
Eigen::MatrixXd Distances(const std::vector<Eigen::Vector2d>& points) {
  const auto n = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd cost(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j)
      cost(i, j) = (points[static_cast<std::size_t>(i)] - points[static_cast<std::size_t>(j)]).norm();
  }
  return cost;
}

// m clusters; cluster i holds the point at angle 2 pi i / m on the unit circle and `decoys` points
// 3-4 m from the centre. Every decoy costs a detour of more than the two chords it could save, and
// points in convex position are best toured in their order round the hull, so the optimum is the
// m-gon's perimeter, 2 m sin(pi / m). The clusters are numbered out of circle order.
GtspInstance CircleWithDecoys(int m, int decoys, std::uint64_t seed) {
  Rng rng = MakeRng(seed, "circle_with_decoys");
  GtspInstance instance;
  std::vector<Eigen::Vector2d> points;
  instance.clusters.resize(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) {
    const int position = (i * 7) % m;  // 7 and m share no factor in these tests
    const double angle = 2.0 * M_PI * position / m;
    instance.clusters[static_cast<std::size_t>(i)].push_back(static_cast<int>(points.size()));
    points.emplace_back(std::cos(angle), std::sin(angle));
    for (int d = 0; d < decoys; ++d) {
      const double radius = 3.0 + UniformUnit(rng), phi = 2.0 * M_PI * UniformUnit(rng);
      instance.clusters[static_cast<std::size_t>(i)].push_back(static_cast<int>(points.size()));
      points.emplace_back(radius * std::cos(phi), radius * std::sin(phi));
    }
  }
  instance.cost = Distances(points);
  return instance;
}

// m clusters of k points each, uniform in the unit square; asymmetric when `asymmetric` (a cost
// per direction, as a joint move up and down a slope can differ).
GtspInstance RandomInstance(int m, int k, bool asymmetric, std::uint64_t seed) {
  Rng rng = MakeRng(seed, "random_gtsp");
  std::vector<Eigen::Vector2d> points;
  GtspInstance instance;
  instance.clusters.resize(static_cast<std::size_t>(m));
  for (int i = 0; i < m * k; ++i) {
    instance.clusters[static_cast<std::size_t>(i % m)].push_back(i);
    const double x = UniformUnit(rng);
    points.emplace_back(x, UniformUnit(rng));
  }
  instance.cost = Distances(points);
  if (asymmetric) {
    for (Eigen::Index i = 0; i < instance.cost.rows(); ++i) {
      for (Eigen::Index j = 0; j < instance.cost.cols(); ++j) instance.cost(i, j) *= 1.0 + 0.5 * UniformUnit(rng);
    }
  }
  return instance;
}

// Each cluster visited once, by one of its own nodes.
void ExpectValidTour(const GtspInstance& instance, const GtspTour& tour) {
  ASSERT_EQ(tour.nodes.size(), instance.clusters.size());
  std::vector<int> visits(instance.clusters.size(), 0);
  for (int node : tour.nodes) {
    for (std::size_t c = 0; c < instance.clusters.size(); ++c) {
      for (int member : instance.clusters[c]) visits[c] += member == node ? 1 : 0;
    }
  }
  for (int v : visits) EXPECT_EQ(v, 1);
  EXPECT_NEAR(tour.cost, TourCost(instance, tour.nodes), 1e-9);
}

TEST(Gtsp, EverySolverFindsTheKnownOptimumOfACircleWithDecoys) {
  for (int m : {5, 9, 12}) {
    const GtspInstance instance = CircleWithDecoys(m, 4, 11);
    const double optimum = 2.0 * m * std::sin(M_PI / m);
    const GtspTour exact = SolveGtspExact(instance);
    ExpectValidTour(instance, exact);
    EXPECT_NEAR(exact.cost, optimum, 1e-9) << m << " clusters";
    const GtspTour search = SolveGtspLargeNeighbourhood(instance);
    ExpectValidTour(instance, search);
    EXPECT_NEAR(search.cost, optimum, 1e-9) << m << " clusters";
  }
  // Beyond the exact solver's reach, the search still finds it.
  const GtspInstance large = CircleWithDecoys(40, 6, 12);
  EXPECT_THROW(SolveGtspExact(large), std::invalid_argument);
  const GtspTour search = SolveGtspLargeNeighbourhood(large);
  ExpectValidTour(large, search);
  EXPECT_NEAR(search.cost, 2.0 * 40 * std::sin(M_PI / 40), 1e-9);
}

// Issue 31's target: the search within 1 % of the optimum on instances of up to 12 clusters. The
// arm's costs (joint-space motion times) are symmetric; on asymmetric costs the search holds no
// such bound (insertions cannot turn a tour round) and is held to beating the greedy baseline.
TEST(Gtsp, TheSearchIsWithinOnePercentOfTheOptimumOnRandomInstances) {
  double worst = 0.0, worst_asymmetric = 0.0, nearest_neighbour_excess = 0.0;
  int instances = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    for (bool asymmetric : {false, true}) {
      const GtspInstance instance = RandomInstance(6 + static_cast<int>(seed % 7), 5, asymmetric, seed);
      const GtspTour exact = SolveGtspExact(instance);
      const GtspTour search = SolveGtspLargeNeighbourhood(instance);
      const GtspTour greedy = SolveGtspNearestNeighbour(instance);
      ExpectValidTour(instance, exact);
      ExpectValidTour(instance, search);
      ExpectValidTour(instance, greedy);
      EXPECT_GE(search.cost, exact.cost - 1e-9);
      EXPECT_LE(search.cost, greedy.cost + 1e-9);
      (asymmetric ? worst_asymmetric : worst) =
          std::max(asymmetric ? worst_asymmetric : worst, search.cost / exact.cost - 1.0);
      if (!asymmetric) {
        nearest_neighbour_excess += greedy.cost / exact.cost - 1.0;
        ++instances;
      }
    }
  }
  std::printf(
      "GTSP, %d symmetric instances of 6-12 clusters: search at most %.3f %% above the optimum, nearest "
      "neighbour %.1f %% above on average; asymmetric: search at most %.2f %% above\n",
      instances, 100.0 * worst, 100.0 * nearest_neighbour_excess / instances, 100.0 * worst_asymmetric);
  EXPECT_LE(worst, 0.01);
}

TEST(Gtsp, ForbiddenTransitionsAreAvoidedWhenATourWithoutThemExists) {
  GtspInstance instance = CircleWithDecoys(8, 2, 3);
  // Forbid the circle's edge from the point at angle 0 to its neighbour at 45 deg (both ways):
  // the tour must go round it.
  const int a = instance.clusters[0][0], b = instance.clusters[7][0];  // positions 0 and 49 % 8 = 1
  instance.cost(a, b) = instance.cost(b, a) = std::numeric_limits<double>::infinity();
  const GtspTour exact = SolveGtspExact(instance);
  ASSERT_TRUE(exact.Feasible());
  const GtspTour search = SolveGtspLargeNeighbourhood(instance);
  ASSERT_TRUE(search.Feasible());
  EXPECT_NEAR(search.cost, exact.cost, 1e-9);
  EXPECT_GT(exact.cost, 2.0 * 8 * std::sin(M_PI / 8) + 1e-6);
}

TEST(Gtsp, TheSameSeedGivesTheSameTour) {
  const GtspInstance instance = RandomInstance(30, 6, false, 5);
  GtspSearchOptions options;
  options.seed = 42;
  const GtspTour first = SolveGtspLargeNeighbourhood(instance, options);
  const GtspTour second = SolveGtspLargeNeighbourhood(instance, options);
  EXPECT_EQ(first.nodes, second.nodes);
  EXPECT_EQ(first.cost, second.cost);
  // And it does better than the greedy baseline on an instance of the trimming's size.
  EXPECT_LT(first.cost, SolveGtspNearestNeighbour(instance).cost);
}

TEST(Gtsp, MalformedInstancesAreRefusedNamingTheProblem) {
  GtspInstance instance = RandomInstance(4, 2, false, 1);
  const auto message = [](const GtspInstance& bad) {
    try {
      ValidateGtsp(bad);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  GtspInstance overlapping = instance;
  overlapping.clusters[1].push_back(overlapping.clusters[0][0]);
  EXPECT_NE(message(overlapping).find("is in clusters 0 and 1"), std::string::npos) << message(overlapping);
  GtspInstance uncovered = instance;
  uncovered.clusters[3].pop_back();
  EXPECT_NE(message(uncovered).find("in no cluster"), std::string::npos) << message(uncovered);
  GtspInstance empty = instance;
  empty.clusters.push_back({});
  EXPECT_NE(message(empty).find("is empty"), std::string::npos) << message(empty);
  GtspInstance negative = instance;
  negative.cost(1, 2) = -1.0;
  EXPECT_NE(message(negative).find("negative"), std::string::npos) << message(negative);
  GtspInstance rectangular = instance;
  rectangular.cost.conservativeResize(8, 7);
  EXPECT_NE(message(rectangular).find("not square"), std::string::npos) << message(rectangular);
  EXPECT_EQ(message(instance), "accepted");
}

}  // namespace
}  // namespace trimbot::trimming
