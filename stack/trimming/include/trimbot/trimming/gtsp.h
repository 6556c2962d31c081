#pragma once
// The Generalized Travelling Salesman Problem (GTSP): nodes in disjoint clusters; a tour visits
// exactly one node of every cluster and returns to its first, at the least total edge cost.
// Trimming poses the cutting path as one (reference deliverable D3.4, Section 1.5): a cluster per
// cutting pose, a node per collision-free inverse-kinematics solution of it, the edge cost the
// joint-space motion time between two solutions. A path that starts at the arm's configuration and
// ends anywhere is a tour through a one-node start cluster whose incoming edges cost nothing.
//
// Three solvers, one tour type:
// - SolveGtspExact: dynamic programming over subsets of clusters (Held-Karp with a node per
//   state), the optimum of small instances, against which the others are checked;
// - SolveGtspNearestNeighbour: the greedy baseline;
// - SolveGtspLargeNeighbourhood: a large-neighbourhood search in the manner of GLNS (Smith and
//   Imeson, "GLNS: An effective large neighborhood search heuristic for the Generalized Traveling
//   Salesman Problem", Computers & Operations Research 87, 2017): remove clusters (randomly, the
//   worst, or a segment), insert them back where and with the node that cost least, choose the
//   best node of every cluster for the visiting order by a shortest path, accept by simulated
//   annealing. Seeded: the same instance and seed give the same tour.
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

namespace trimbot::trimming {

struct GtspInstance {
  std::vector<std::vector<int>> clusters;  // the nodes of each cluster (indices into cost)
  Eigen::MatrixXd cost;                    // cost(i, j): from node i to node j; may be asymmetric;
                                           // +infinity: not allowed (a transition in collision)
};

struct GtspTour {
  std::vector<int> nodes;  // one node per cluster, in visiting order; the tour returns to nodes[0]
  double cost = std::numeric_limits<double>::infinity();  // +infinity: no tour of finite cost
  bool Feasible() const { return cost < std::numeric_limits<double>::infinity(); }
};

// Throws std::invalid_argument naming the problem: clusters empty, overlapping or not covering
// every node, a cost matrix that is not square, negative or NaN.
void ValidateGtsp(const GtspInstance& instance);

// Cost of visiting `nodes` in order and returning to the first.
double TourCost(const GtspInstance& instance, const std::vector<int>& nodes);

// The optimum, by dynamic programming in O(2^m n^2) time and O(2^m n) memory for m clusters and
// n nodes; instances with more than `max_clusters` clusters are refused (std::invalid_argument).
GtspTour SolveGtspExact(const GtspInstance& instance, int max_clusters = 14);

// From each node of the first cluster, repeatedly to the cheapest node of a cluster not visited
// yet; the cheapest of those tours.
GtspTour SolveGtspNearestNeighbour(const GtspInstance& instance);

// Defaults are GLNS's "default" mode (its parameter_defaults): 5 cold and 3 warm restarts, 60 iterations per
// cluster, stop after 30 per cluster without a better tour, 2 to 30 % of the clusters removed.
struct GtspSearchOptions {
  std::uint64_t seed = 1;
  int restarts = 5;                         // independent searches, each from a randomized insertion tour ...
  int warm_restarts = 3;                    // ... annealed again this often from its best, cooler
  int iterations_per_cluster = 60;          // per restart
  int stalled_iterations_per_cluster = 30;  // per restart, without bettering its best
  double max_removed_share = 0.3;           // at most this share of the clusters removed at once
  double insertion_noise = 0.5;             // half the insertions raise each candidate's cost by up to this share
  // Simulated annealing, as a share of the tour's cost: at the start a tour 5 % costlier is accepted
  // with probability 1/2 (0.05 x 1.442), by the end one 50 % costlier with probability 0.05 %.
  double initial_temperature = 0.0721;
  double final_temperature = 0.000721;
};

GtspTour SolveGtspLargeNeighbourhood(const GtspInstance& instance, const GtspSearchOptions& options = {});

// The best node of every cluster for a fixed visiting order (by a shortest path through the
// clusters' nodes from each node of the smallest cluster): `tour->nodes` keeps its clusters and
// order, its nodes and cost change when that is cheaper.
void OptimizeNodesForOrder(const GtspInstance& instance, GtspTour* tour);

}  // namespace trimbot::trimming
