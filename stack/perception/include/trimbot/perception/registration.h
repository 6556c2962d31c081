#pragma once
// Rigid registration of two point clouds that carry per-point uncertainty: find R, t with
// x ~ R y + t (the source cloud Y moved onto the target cloud X).
//
// DUGMA (Dynamic Uncertainty-based Gaussian Mixture Alignment, reference deliverable D3.4
// section 1) as EM: the E-step weighs every pair (x_i, y_j) by the Gaussian of their difference
// under both points' covariances, Sigma_x + R Sigma_y R^T, normalized per source point against an
// outlier term; the M-step finds R, t minimizing the weighted Mahalanobis distances (closed form
// when all covariances are isotropic, a Gauss-Newton step otherwise). Pairs beyond
// `truncation_sigmas` are negligible and never formed: each source point only meets its k nearest
// target points (k-d tree), so the cost is near-linear in the cloud sizes instead of N x M. An
// annealing term (an isotropic spread added to every pair, shrinking each iteration) widens the
// basin at the start - the "dynamic" part.
//
// The baselines go through the same API: Open3D's ICP (point-to-point, point-to-plane) and
// generalized ICP, coarse to fine from the target's RMS radius down to 3 point spacings.
#include <Eigen/Geometry>
#include <stdexcept>
#include <string>

#include "trimbot/perception/point_cloud.h"

namespace trimbot::perception {

enum class RegistrationMethod { kDugma, kIcpPointToPoint, kIcpPointToPlane, kGeneralizedIcp };

struct RegistrationOptions {
  RegistrationMethod method = RegistrationMethod::kDugma;
  int max_iterations = 100;
  double tolerance = 1e-5;          // rad + m: stop when an iteration moves less than this
  int neighbours = 10;              // k nearest target points per source point
  int max_source_points = 10000;    // DUGMA uses at most this many source points (0: all)
  double truncation_sigmas = 3.0;   // pairs farther apart (Mahalanobis) are left out
  double outlier_weight = 0.1;      // relative weight of the outlier term in the E-step
  // Annealing: initial extra spread (m); < 0 picks it from the initial misalignment (the median
  // distance of the source points to their nearest target point) and the size of the target
  // (30 % of its RMS radius), whichever is larger.
  double anneal_start = -1.0;
  double anneal_factor = 0.9;       // per iteration
  // Covariances given as relative weights (as in the DUGMA Kinect data set) are scaled so that
  // each cloud's median point variance equals the square of its own median point spacing.
  bool relative_covariances = false;
  // Surface patches (DUGMA): two clouds sample a surface at different places, so their points do
  // not correspond one to one and only the distance across the surface is evidence. Each point's
  // covariance keeps its variance along the local normal (from its 10 nearest neighbours in its
  // own cloud) and gets a standard deviation of `surface_spacings` point spacings along the surface
  // (as generalized ICP's plane-to-plane term). Without it, partial views of a rounded bush pulled
  // DUGMA off the truth even when started on it. 0 keeps the covariances as given.
  double surface_spacings = 10.0;
  double max_variance = 1e4;        // m^2 (or relative units); larger marks an unusable point
  // Register the pair both ways and call the result untrusted when the two disagree by more than
  // max_inconsistency_deg (twice the time). If both were within 5 deg of the truth they would
  // differ by at most 10: more means at least one is off by more than 5 deg (the success bound).
  bool check_consistency = false;
  double max_inconsistency_deg = 10.0;
};

struct RegistrationResult {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // x = transform * y
  int iterations = 0;               // EM iterations (DUGMA); the stages' budget (ICP: Open3D reports no count)
  bool converged = false;
  double final_cost = 0.0;          // weighted mean squared Mahalanobis distance of the pairs
  int pairs = 0;                    // pairs with weight in the last E-step
  double matched_fraction = 0.0;    // of the source points, those with a pair in the last E-step (DUGMA)
  // With check_consistency: the forward result composed with the reverse one (identity when they
  // agree), and whether to trust the result, with the reason when not.
  double consistency_deg = 0.0, consistency_m = 0.0;
  bool trusted = true;
  std::string doubt;
  CleanReport target_points, source_points;  // what was usable / dropped
};

// Bad input that leaves nothing to register (e.g. an empty cloud after dropping unusable points).
class RegistrationError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

RegistrationResult Register(const PointCloud& target, const PointCloud& source, const Eigen::Isometry3d& initial,
                            const RegistrationOptions& options = {});


}  // namespace trimbot::perception
