#include "evaluation/statistics.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "trimbot/common/random.h"

namespace trimbot::scenarios {
namespace {

double LogChoose(int n, int k) { return std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0); }

Interval Percentiles(std::vector<double> values) {
  if (values.empty()) return {};
  std::sort(values.begin(), values.end());
  const auto at = [&](double q) { return values[static_cast<std::size_t>(std::floor(q * (values.size() - 1)))]; };
  return {at(0.025), at(0.975)};
}

// A uniform index in [0, n) from 64 random bits (portable, unlike std::uniform_int_distribution).
std::size_t Index(Rng& rng, std::size_t n) { return static_cast<std::size_t>(rng() % n); }

std::vector<double> BootstrapMeans(const std::vector<double>& samples, Rng& rng, int resamples) {
  std::vector<double> means;
  means.reserve(static_cast<std::size_t>(resamples));
  for (int r = 0; r < resamples; ++r) {
    double sum = 0.0;
    for (std::size_t i = 0; i < samples.size(); ++i) sum += samples[Index(rng, samples.size())];
    means.push_back(sum / static_cast<double>(samples.size()));
  }
  return means;
}

// Ranks (1-based, ties averaged) of the pooled values; returns the sum of the ranks of b.
double RankSumOfB(const std::vector<double>& a, const std::vector<double>& b, double* tie_term) {
  std::vector<std::pair<double, int>> pooled;
  for (double v : a) pooled.push_back({v, 0});
  for (double v : b) pooled.push_back({v, 1});
  std::sort(pooled.begin(), pooled.end());
  double sum_b = 0.0;
  *tie_term = 0.0;
  for (std::size_t i = 0; i < pooled.size();) {
    std::size_t j = i;
    while (j < pooled.size() && pooled[j].first == pooled[i].first) ++j;
    const double rank = 0.5 * static_cast<double>(i + 1 + j);
    const double t = static_cast<double>(j - i);
    *tie_term += t * t * t - t;
    for (std::size_t k = i; k < j; ++k) sum_b += pooled[k].second == 1 ? rank : 0.0;
    i = j;
  }
  return sum_b;
}

}  // namespace

double Mean(const std::vector<double>& values) {
  return values.empty() ? 0.0 : std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double position = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, values.size() - 1);
  return values[below] + (position - static_cast<double>(below)) * (values[above] - values[below]);
}

Interval WilsonInterval(int successes, int n, double z) {
  if (n <= 0) return {0.0, 1.0};
  const double p = static_cast<double>(successes) / n, z2 = z * z;
  const double centre = (p + z2 / (2.0 * n)) / (1.0 + z2 / n);
  const double half = z * std::sqrt(p * (1.0 - p) / n + z2 / (4.0 * n * n)) / (1.0 + z2 / n);
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

Interval BootstrapMeanInterval(const std::vector<double>& samples, std::uint64_t seed, int resamples) {
  if (samples.empty()) return {};
  Rng rng = MakeRng(seed, "bootstrap");
  return Percentiles(BootstrapMeans(samples, rng, resamples));
}

Interval BootstrapDifferenceInterval(const std::vector<double>& a, const std::vector<double>& b, std::uint64_t seed,
                                     int resamples) {
  if (a.empty() || b.empty()) return {};
  Rng rng = MakeRng(seed, "bootstrap_difference");
  const std::vector<double> ma = BootstrapMeans(a, rng, resamples), mb = BootstrapMeans(b, rng, resamples);
  std::vector<double> differences(ma.size());
  for (std::size_t i = 0; i < ma.size(); ++i) differences[i] = mb[i] - ma[i];
  return Percentiles(differences);
}

double FisherLowerP(int sa, int na, int sb, int nb) {
  // Successes in b ~ hypergeometric(total successes K, population N, draws nb).
  const int N = na + nb, K = sa + sb;
  if (N == 0) return 1.0;
  double p = 0.0;
  for (int x = std::max(0, K - na); x <= std::min(K, nb) && x <= sb; ++x) {
    p += std::exp(LogChoose(K, x) + LogChoose(N - K, nb - x) - LogChoose(N, nb));
  }
  return std::min(1.0, p);
}

double MannWhitneyGreaterP(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t na = a.size(), nb = b.size();
  if (na == 0 || nb == 0) return 1.0;
  double tie_term = 0.0;
  const double observed = RankSumOfB(a, b, &tie_term);
  if (na + nb <= 20) {
    // Exact: every way to choose which pooled values are b's, counted by rank sum >= observed.
    std::vector<double> pooled(a);
    pooled.insert(pooled.end(), b.begin(), b.end());
    std::vector<int> pick(na + nb, 0);
    std::fill(pick.end() - static_cast<std::ptrdiff_t>(nb), pick.end(), 1);
    long total = 0, extreme = 0;
    do {
      std::vector<double> xa, xb;
      for (std::size_t i = 0; i < pooled.size(); ++i) (pick[i] ? xb : xa).push_back(pooled[i]);
      double unused = 0.0;
      ++total;
      if (RankSumOfB(xa, xb, &unused) >= observed - 1e-9) ++extreme;
    } while (std::next_permutation(pick.begin(), pick.end()));
    return static_cast<double>(extreme) / static_cast<double>(total);
  }
  const double n = static_cast<double>(na + nb);
  const double u = observed - nb * (nb + 1.0) / 2.0;
  const double mean = na * nb / 2.0;
  const double variance = na * nb / 12.0 * ((n + 1.0) - tie_term / (n * (n - 1.0)));
  if (variance <= 0.0) return 1.0;
  const double z = (u - mean - 0.5) / std::sqrt(variance);  // continuity correction
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

double FisherPower(double p_a, double p_b, int n, double alpha) {
  double power = 0.0;
  for (int sa = 0; sa <= n; ++sa) {
    const double pa = std::exp(LogChoose(n, sa) + sa * std::log(std::max(p_a, 1e-300)) +
                               (n - sa) * std::log(std::max(1.0 - p_a, 1e-300)));
    if (pa < 1e-15) continue;
    for (int sb = 0; sb <= n; ++sb) {
      if (FisherLowerP(sa, n, sb, n) > alpha) continue;
      power += pa * std::exp(LogChoose(n, sb) + sb * std::log(std::max(p_b, 1e-300)) +
                             (n - sb) * std::log(std::max(1.0 - p_b, 1e-300)));
    }
  }
  return std::min(1.0, power);
}

int TrialsToDetect(double p_a, double p_b, double alpha, double power, int max_n) {
  for (int n = 1; n <= max_n; ++n) {
    if (FisherPower(p_a, p_b, n, alpha) >= power) return n;
  }
  return -1;
}

}  // namespace trimbot::scenarios
