#include "trimbot/trimming/gtsp.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "trimbot/common/random.h"

namespace trimbot::trimming {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The cluster of every node.
std::vector<int> ClusterOfNodes(const GtspInstance& instance) {
  std::vector<int> cluster_of(static_cast<std::size_t>(instance.cost.rows()), -1);
  for (std::size_t c = 0; c < instance.clusters.size(); ++c) {
    for (int node : instance.clusters[c]) cluster_of[static_cast<std::size_t>(node)] = static_cast<int>(c);
  }
  return cluster_of;
}

// The search works on finite costs: a forbidden edge costs more than any tour of allowed ones, so
// insertion and removal deltas stay numbers; the tour's true cost is taken from the instance.
Eigen::MatrixXd FiniteCosts(const Eigen::MatrixXd& cost) {
  double largest = 0.0;
  for (int i = 0; i < cost.size(); ++i) {
    if (std::isfinite(cost.data()[i])) largest = std::max(largest, cost.data()[i]);
  }
  const double forbidden = (1.0 + largest) * static_cast<double>(std::max<Eigen::Index>(1, cost.rows())) * 10.0;
  return cost.unaryExpr([forbidden](double c) { return std::isfinite(c) ? c : forbidden; });
}

double CycleCost(const Eigen::MatrixXd& w, const std::vector<int>& nodes) {
  double total = 0.0;
  for (std::size_t i = 0; i < nodes.size(); ++i) total += w(nodes[i], nodes[(i + 1) % nodes.size()]);
  return total;
}

// Uniform integer in [0, n).
int UniformIndex(Rng& rng, int n) { return std::min(n - 1, static_cast<int>(UniformUnit(rng) * n)); }

// The cost of putting `node` between the tour's nodes at position - 1 and position (cyclically).
double InsertionDelta(const Eigen::MatrixXd& w, const std::vector<int>& nodes, std::size_t position, int node) {
  if (nodes.empty()) return w(node, node);
  const int before = nodes[(position + nodes.size() - 1) % nodes.size()];
  const int after = nodes[position % nodes.size()];
  return w(before, node) + w(node, after) - w(before, after);
}

struct Insertion {
  std::size_t position = 0;
  int node = -1;
  double delta = kInfinity;
};

// The cheapest place and node for a cluster. With `noise` > 0 each candidate's cost is raised by up
// to that share of itself (GLNS's insertion noise): re-inserted greedily, a tour would mostly come
// back as it was.
Insertion CheapestInsertion(const Eigen::MatrixXd& w, const std::vector<int>& nodes, const std::vector<int>& cluster,
                            double noise = 0.0, Rng* rng = nullptr) {
  Insertion best;
  double best_noised = kInfinity;
  const std::size_t positions = std::max<std::size_t>(1, nodes.size());
  for (std::size_t p = 0; p < positions; ++p) {
    for (int node : cluster) {
      const double delta = InsertionDelta(w, nodes, p, node);
      const double noised = noise > 0.0 ? delta + noise * UniformUnit(*rng) * std::abs(delta) : delta;
      if (noised < best_noised) {
        best = {p, node, delta};
        best_noised = noised;
      }
    }
  }
  return best;
}

// What leaving out the node at `index` saves.
double RemovalSaving(const Eigen::MatrixXd& w, const std::vector<int>& nodes, std::size_t index) {
  const std::size_t n = nodes.size();
  if (n < 2) return 0.0;
  const int before = nodes[(index + n - 1) % n], node = nodes[index], after = nodes[(index + 1) % n];
  return w(before, node) + w(node, after) - w(before, after);
}

// Removes `count` clusters from the tour by one of GLNS's three rules; returns their indices.
std::vector<int> RemoveClusters(const Eigen::MatrixXd& w, const std::vector<int>& cluster_of, int count, Rng& rng,
                                std::vector<int>* nodes) {
  std::vector<int> removed;
  const int rule = UniformIndex(rng, 3);
  if (rule == 0) {  // segment: consecutive clusters from a random start
    const int start = UniformIndex(rng, static_cast<int>(nodes->size()));
    std::vector<int> kept;
    for (int i = 0; i < static_cast<int>(nodes->size()); ++i) {
      const int offset = (i - start + static_cast<int>(nodes->size())) % static_cast<int>(nodes->size());
      if (offset < count) {
        removed.push_back(cluster_of[static_cast<std::size_t>((*nodes)[static_cast<std::size_t>(i)])]);
      } else {
        kept.push_back((*nodes)[static_cast<std::size_t>(i)]);
      }
    }
    *nodes = kept;
    return removed;
  }
  for (int k = 0; k < count; ++k) {
    std::size_t index = static_cast<std::size_t>(UniformIndex(rng, static_cast<int>(nodes->size())));
    if (rule == 1) {  // worst: the node whose leaving saves most, among a few drawn at random
      for (int draw = 0; draw < 3; ++draw) {
        const auto other = static_cast<std::size_t>(UniformIndex(rng, static_cast<int>(nodes->size())));
        if (RemovalSaving(w, *nodes, other) > RemovalSaving(w, *nodes, index)) index = other;
      }
    }
    removed.push_back(cluster_of[static_cast<std::size_t>((*nodes)[index])]);
    nodes->erase(nodes->begin() + static_cast<std::ptrdiff_t>(index));
  }
  return removed;
}

// Inserts the clusters back, each where and with the node that costs least; in random order, or
// the cluster cheapest to insert first.
void InsertClusters(const Eigen::MatrixXd& w, const GtspInstance& instance, std::vector<int> clusters, double noise,
                    Rng& rng, std::vector<int>* nodes) {
  const bool cheapest_first = UniformUnit(rng) < 0.5;
  if (UniformUnit(rng) < 0.5) noise = 0.0;
  while (!clusters.empty()) {
    std::size_t pick = static_cast<std::size_t>(UniformIndex(rng, static_cast<int>(clusters.size())));
    Insertion insertion =
        CheapestInsertion(w, *nodes, instance.clusters[static_cast<std::size_t>(clusters[pick])], noise, &rng);
    if (cheapest_first) {
      for (std::size_t i = 0; i < clusters.size(); ++i) {
        const Insertion candidate =
            CheapestInsertion(w, *nodes, instance.clusters[static_cast<std::size_t>(clusters[i])], noise, &rng);
        if (candidate.delta < insertion.delta) {
          insertion = candidate;
          pick = i;
        }
      }
    }
    nodes->insert(nodes->begin() + static_cast<std::ptrdiff_t>(insertion.position), insertion.node);
    clusters.erase(clusters.begin() + static_cast<std::ptrdiff_t>(pick));
  }
}

// Reverses the segment of the tour that saves most (2-opt; for asymmetric costs the segment's own
// edges change direction, counted from prefix sums of both directions), until none saves.
void ReverseSegments(const Eigen::MatrixXd& w, std::vector<int>* nodes) {
  const std::size_t m = nodes->size();
  for (bool improved = m > 3; improved;) {
    improved = false;
    std::vector<double> forward(m, 0.0), backward(m, 0.0);  // along the tour up to position k
    for (std::size_t k = 1; k < m; ++k) {
      forward[k] = forward[k - 1] + w((*nodes)[k - 1], (*nodes)[k]);
      backward[k] = backward[k - 1] + w((*nodes)[k], (*nodes)[k - 1]);
    }
    double best = -1e-12;
    std::size_t best_i = 0, best_j = 0;
    for (std::size_t i = 1; i + 1 < m; ++i) {  // position 0 stays: a cycle's reversal is the same cycle
      for (std::size_t j = i + 1; j < m; ++j) {
        const int before = (*nodes)[i - 1], after = (*nodes)[(j + 1) % m];
        const int first = (*nodes)[i], last = (*nodes)[j];
        const double delta = w(before, last) + w(first, after) - w(before, first) - w(last, after) +
                             (backward[j] - backward[i]) - (forward[j] - forward[i]);
        if (delta < best) {
          best = delta;
          best_i = i;
          best_j = j;
        }
      }
    }
    if (best_j > best_i) {
      std::reverse(nodes->begin() + static_cast<std::ptrdiff_t>(best_i),
                   nodes->begin() + static_cast<std::ptrdiff_t>(best_j) + 1);
      improved = true;
    }
  }
}

// Takes every cluster out in turn and puts it back where it costs least, until no move helps.
void MoveClusters(const Eigen::MatrixXd& w, const GtspInstance& instance, const std::vector<int>& cluster_of,
                  std::vector<int>* nodes) {
  for (bool improved = true; improved;) {
    improved = false;
    for (std::size_t i = 0; i < nodes->size() && nodes->size() > 2; ++i) {
      const double saving = RemovalSaving(w, *nodes, i);
      const int cluster = cluster_of[static_cast<std::size_t>((*nodes)[i])];
      std::vector<int> without = *nodes;
      without.erase(without.begin() + static_cast<std::ptrdiff_t>(i));
      const Insertion insertion = CheapestInsertion(w, without, instance.clusters[static_cast<std::size_t>(cluster)]);
      if (insertion.delta < saving - 1e-12 * (1.0 + std::abs(saving))) {
        without.insert(without.begin() + static_cast<std::ptrdiff_t>(insertion.position), insertion.node);
        *nodes = without;
        improved = true;
      }
    }
  }
}

void OptimizeNodes(const Eigen::MatrixXd& w, const GtspInstance& instance, const std::vector<int>& cluster_of,
                   std::vector<int>* nodes) {
  const std::size_t m = nodes->size();
  if (m < 2) return;
  // Start at the smallest cluster: the shortest paths are run once per node of it.
  std::size_t first = 0;
  for (std::size_t i = 1; i < m; ++i) {
    if (instance.clusters[static_cast<std::size_t>(cluster_of[static_cast<std::size_t>((*nodes)[i])])].size() <
        instance.clusters[static_cast<std::size_t>(cluster_of[static_cast<std::size_t>((*nodes)[first])])].size())
      first = i;
  }
  std::vector<const std::vector<int>*> order;
  for (std::size_t i = 0; i < m; ++i)
    order.push_back(
        &instance.clusters[static_cast<std::size_t>(cluster_of[static_cast<std::size_t>((*nodes)[(first + i) % m])])]);
  double best_cost = CycleCost(w, *nodes);
  std::vector<int> best_nodes;
  for (int start : *order[0]) {
    // distance[k]: cheapest path from start to node k of the current cluster; parents per layer.
    std::vector<double> distance{0.0};
    std::vector<int> previous_nodes{start};
    std::vector<std::vector<int>> parent(m);
    for (std::size_t layer = 1; layer < m; ++layer) {
      const std::vector<int>& cluster = *order[layer];
      std::vector<double> next(cluster.size(), kInfinity);
      parent[layer].assign(cluster.size(), 0);
      for (std::size_t k = 0; k < cluster.size(); ++k) {
        for (std::size_t j = 0; j < previous_nodes.size(); ++j) {
          const double d = distance[j] + w(previous_nodes[j], cluster[k]);
          if (d < next[k]) {
            next[k] = d;
            parent[layer][k] = static_cast<int>(j);
          }
        }
      }
      distance = next;
      previous_nodes = cluster;
    }
    std::size_t last = 0;
    double total = kInfinity;
    for (std::size_t k = 0; k < previous_nodes.size(); ++k) {
      const double d = distance[k] + w(previous_nodes[k], start);
      if (d < total) {
        total = d;
        last = k;
      }
    }
    if (total < best_cost - 1e-12 * (1.0 + best_cost)) {
      best_cost = total;
      best_nodes.assign(m, start);
      std::size_t k = last;
      for (std::size_t layer = m - 1; layer >= 1; --layer) {
        best_nodes[layer] = (*order[layer])[k];
        k = static_cast<std::size_t>(parent[layer][k]);
      }
    }
  }
  if (!best_nodes.empty()) *nodes = best_nodes;
}

GtspTour Finish(const GtspInstance& instance, std::vector<int> nodes) {
  GtspTour tour;
  tour.cost = TourCost(instance, nodes);
  tour.nodes = std::move(nodes);
  return tour;
}

}  // namespace

void ValidateGtsp(const GtspInstance& instance) {
  const Eigen::Index n = instance.cost.rows();
  if (instance.cost.cols() != n)
    throw std::invalid_argument("GTSP: the cost matrix is " + std::to_string(n) + " x " +
                                std::to_string(instance.cost.cols()) + ", not square");
  if (instance.clusters.empty()) throw std::invalid_argument("GTSP: no clusters");
  std::vector<int> seen(static_cast<std::size_t>(n), -1);
  for (std::size_t c = 0; c < instance.clusters.size(); ++c) {
    if (instance.clusters[c].empty()) throw std::invalid_argument("GTSP: cluster " + std::to_string(c) + " is empty");
    for (int node : instance.clusters[c]) {
      if (node < 0 || node >= n)
        throw std::invalid_argument("GTSP: cluster " + std::to_string(c) + " names node " + std::to_string(node) +
                                    ", outside the " + std::to_string(n) + " nodes of the cost matrix");
      if (seen[static_cast<std::size_t>(node)] >= 0)
        throw std::invalid_argument("GTSP: node " + std::to_string(node) + " is in clusters " +
                                    std::to_string(seen[static_cast<std::size_t>(node)]) + " and " + std::to_string(c));
      seen[static_cast<std::size_t>(node)] = static_cast<int>(c);
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (seen[static_cast<std::size_t>(i)] < 0)
      throw std::invalid_argument("GTSP: node " + std::to_string(i) + " is in no cluster");
    for (Eigen::Index j = 0; j < n; ++j) {
      if (std::isnan(instance.cost(i, j)) || instance.cost(i, j) < 0.0)
        throw std::invalid_argument("GTSP: cost(" + std::to_string(i) + ", " + std::to_string(j) +
                                    ") is negative or NaN");
    }
  }
}

double TourCost(const GtspInstance& instance, const std::vector<int>& nodes) {
  return nodes.empty() ? kInfinity : CycleCost(instance.cost, nodes);
}

GtspTour SolveGtspExact(const GtspInstance& instance, int max_clusters) {
  ValidateGtsp(instance);
  const int m = static_cast<int>(instance.clusters.size());
  if (m > max_clusters)
    throw std::invalid_argument("GTSP: the exact solver takes at most " + std::to_string(max_clusters) +
                                " clusters, not " + std::to_string(m));
  const Eigen::MatrixXd w = FiniteCosts(instance.cost);
  const std::vector<int> cluster_of = ClusterOfNodes(instance);
  const int n = static_cast<int>(w.rows());
  const std::size_t masks = std::size_t{1} << (m - 1);  // subsets of the clusters 1..m-1
  std::vector<int> best_nodes;
  double best = kInfinity;
  if (m == 1) {
    for (int v : instance.clusters[0]) {
      if (w(v, v) < best) {
        best = w(v, v);
        best_nodes = {v};
      }
    }
    return Finish(instance, best_nodes);
  }
  std::vector<double> cost(masks * static_cast<std::size_t>(n));
  std::vector<int> parent(masks * static_cast<std::size_t>(n));
  const auto at = [n](std::size_t mask, int node) {
    return mask * static_cast<std::size_t>(n) + static_cast<std::size_t>(node);
  };
  for (int start : instance.clusters[0]) {
    std::fill(cost.begin(), cost.end(), kInfinity);
    for (int c = 1; c < m; ++c) {
      for (int v : instance.clusters[static_cast<std::size_t>(c)]) {
        cost[at(std::size_t{1} << (c - 1), v)] = w(start, v);
        parent[at(std::size_t{1} << (c - 1), v)] = start;
      }
    }
    for (std::size_t mask = 1; mask < masks; ++mask) {
      for (int c = 1; c < m; ++c) {
        if (!(mask & (std::size_t{1} << (c - 1)))) continue;
        for (int v : instance.clusters[static_cast<std::size_t>(c)]) {
          const double here = cost[at(mask, v)];
          if (here == kInfinity) continue;
          for (int d = 1; d < m; ++d) {
            if (mask & (std::size_t{1} << (d - 1))) continue;
            const std::size_t next = mask | (std::size_t{1} << (d - 1));
            for (int u : instance.clusters[static_cast<std::size_t>(d)]) {
              const double candidate = here + w(v, u);
              if (candidate < cost[at(next, u)]) {
                cost[at(next, u)] = candidate;
                parent[at(next, u)] = v;
              }
            }
          }
        }
      }
    }
    for (int v = 0; v < n; ++v) {
      if (cluster_of[static_cast<std::size_t>(v)] == 0) continue;
      const double total = cost[at(masks - 1, v)] + w(v, start);
      if (total >= best) continue;
      best = total;
      best_nodes.assign(static_cast<std::size_t>(m), start);
      std::size_t mask = masks - 1;
      int node = v;
      for (int i = m - 1; i >= 1; --i) {
        best_nodes[static_cast<std::size_t>(i)] = node;
        const int previous = parent[at(mask, node)];
        mask &= ~(std::size_t{1} << (cluster_of[static_cast<std::size_t>(node)] - 1));
        node = previous;
      }
    }
  }
  return Finish(instance, best_nodes);
}

GtspTour SolveGtspNearestNeighbour(const GtspInstance& instance) {
  ValidateGtsp(instance);
  const Eigen::MatrixXd w = FiniteCosts(instance.cost);
  const std::vector<int> cluster_of = ClusterOfNodes(instance);
  std::vector<int> best_nodes;
  double best = kInfinity;
  for (int start : instance.clusters[0]) {
    std::vector<bool> visited(instance.clusters.size(), false);
    visited[0] = true;
    std::vector<int> nodes{start};
    for (std::size_t step = 1; step < instance.clusters.size(); ++step) {
      int next = -1;
      for (int v = 0; v < static_cast<int>(w.rows()); ++v) {
        if (!visited[static_cast<std::size_t>(cluster_of[static_cast<std::size_t>(v)])] &&
            (next < 0 || w(nodes.back(), v) < w(nodes.back(), next)))
          next = v;
      }
      visited[static_cast<std::size_t>(cluster_of[static_cast<std::size_t>(next)])] = true;
      nodes.push_back(next);
    }
    const double total = CycleCost(w, nodes);
    if (total < best) {
      best = total;
      best_nodes = nodes;
    }
  }
  return Finish(instance, best_nodes);
}

void OptimizeNodesForOrder(const GtspInstance& instance, GtspTour* tour) {
  ValidateGtsp(instance);
  OptimizeNodes(FiniteCosts(instance.cost), instance, ClusterOfNodes(instance), &tour->nodes);
  tour->cost = TourCost(instance, tour->nodes);
}

// The local optimum near a tour: reversed segments, the best nodes for the order, clusters moved,
// until none of them helps.
void ImproveLocally(const Eigen::MatrixXd& w, const GtspInstance& instance, const std::vector<int>& cluster_of,
                    std::vector<int>* nodes) {
  for (double cost = CycleCost(w, *nodes);;) {
    ReverseSegments(w, nodes);
    OptimizeNodes(w, instance, cluster_of, nodes);
    MoveClusters(w, instance, cluster_of, nodes);
    const double improved = CycleCost(w, *nodes);
    if (improved >= cost - 1e-12 * (1.0 + cost)) return;
    cost = improved;
  }
}

GtspTour SolveGtspLargeNeighbourhood(const GtspInstance& instance, const GtspSearchOptions& options) {
  ValidateGtsp(instance);
  const Eigen::MatrixXd w = FiniteCosts(instance.cost);
  const std::vector<int> cluster_of = ClusterOfNodes(instance);
  const int m = static_cast<int>(instance.clusters.size());
  Rng rng = MakeRng(options.seed, "gtsp_large_neighbourhood");
  std::vector<int> all(static_cast<std::size_t>(m));
  std::iota(all.begin(), all.end(), 0);
  const int max_removed = std::max(1, std::min(m - 1, static_cast<int>(std::lround(options.max_removed_share * m))));
  const int min_removed = max_removed > 1 ? 2 : 1;
  const int iterations = options.iterations_per_cluster * m;
  const int max_stalled = options.stalled_iterations_per_cluster * m;
  std::vector<int> best_nodes;
  double best = kInfinity;
  const double cooling =
      std::pow(options.final_temperature / options.initial_temperature, 1.0 / std::max(1, iterations));
  const double accept_any = 10.0 / std::max(1, iterations);  // GLNS's prob_accept
  for (int restart = 0; restart < std::max(1, options.restarts); ++restart) {
    std::vector<int> restart_best;
    InsertClusters(w, instance, all, options.insertion_noise, rng, &restart_best);
    ImproveLocally(w, instance, cluster_of, &restart_best);
    double restart_best_cost = CycleCost(w, restart_best);
    // The first pass anneals from the full temperature; each warm pass from the restart's best tour,
    // from the temperature halfway down.
    for (int pass = 0; pass <= options.warm_restarts && m > 1; ++pass) {
      std::vector<int> current = restart_best;
      double current_cost = restart_best_cost;
      double temperature =
          options.initial_temperature * current_cost * (pass == 0 ? 1.0 : std::pow(cooling, iterations / 2));
      for (int iteration = 0, stalled = 0; iteration < iterations && stalled < max_stalled;
           ++iteration, temperature *= cooling) {
        std::vector<int> candidate = current;
        const int count = min_removed + UniformIndex(rng, max_removed - min_removed + 1);
        const std::vector<int> removed = RemoveClusters(w, cluster_of, count, rng, &candidate);
        InsertClusters(w, instance, removed, options.insertion_noise, rng, &candidate);
        OptimizeNodes(w, instance, cluster_of, &candidate);
        const double candidate_cost = CycleCost(w, candidate);
        if (candidate_cost < current_cost || UniformUnit(rng) < accept_any ||
            UniformUnit(rng) < std::exp((current_cost - candidate_cost) / temperature)) {
          current = std::move(candidate);
          current_cost = candidate_cost;
        }
        if (current_cost < restart_best_cost - 1e-12 * (1.0 + restart_best_cost)) {
          ImproveLocally(w, instance, cluster_of, &current);  // as GLNS optimizes each new best fully
          current_cost = CycleCost(w, current);
          restart_best = current;
          restart_best_cost = current_cost;
          stalled = 0;
        } else {
          ++stalled;
        }
      }
    }
    if (restart_best_cost < best) {
      best = restart_best_cost;
      best_nodes = restart_best;
    }
  }
  return Finish(instance, best_nodes);
}

}  // namespace trimbot::trimming
