#pragma once
// Small-sample statistics for comparing batches of trials: intervals for rates and means, tests
// for "worse than the baseline", and the power of those tests. Trials are the independent unit
// (error samples within a trial are correlated), so errors are compared as per-trial means.
// Everything here is deterministic: the bootstrap draws from a fixed seed.
#include <cstdint>
#include <utility>
#include <vector>

namespace trimbot::scenarios {

struct Interval {
  double low = 0.0, high = 0.0;
};

// Arithmetic mean (0 for no values).
double Mean(const std::vector<double>& values);
// The q-quantile (0..1) by linear interpolation between order statistics (0 for no values).
double Percentile(std::vector<double> values, double q);

// 95 % (z = 1.96) Wilson score interval of a rate of `successes` in `n`.
Interval WilsonInterval(int successes, int n, double z = 1.959964);

// Percentile bootstrap interval (95 %) of the mean of `samples` (empty -> [0, 0]).
Interval BootstrapMeanInterval(const std::vector<double>& samples, std::uint64_t seed = 1, int resamples = 2000);
// Percentile bootstrap interval (95 %) of mean(b) - mean(a).
Interval BootstrapDifferenceInterval(const std::vector<double>& a, const std::vector<double>& b, std::uint64_t seed = 1,
                                     int resamples = 2000);

// One-sided Fisher exact test that the success rate of b (sb of nb) is lower than that of a
// (sa of na): P(X_b <= sb) under the hypergeometric null with the margins fixed.
double FisherLowerP(int sa, int na, int sb, int nb);

// One-sided Mann-Whitney U test that values in b tend to be larger than in a: exact permutation
// distribution for n_a + n_b <= 20, normal approximation with tie correction above.
double MannWhitneyGreaterP(const std::vector<double>& a, const std::vector<double>& b);

// Power of FisherLowerP at level alpha with n trials on each side when the true rates are p_a
// and p_b (exact, summing over all outcomes).
double FisherPower(double p_a, double p_b, int n, double alpha);
// Smallest n (up to max_n) with FisherPower >= power, or -1.
int TrialsToDetect(double p_a, double p_b, double alpha, double power = 0.8, int max_n = 200);

}  // namespace trimbot::scenarios
