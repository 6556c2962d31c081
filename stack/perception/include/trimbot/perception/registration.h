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
// basin at the start - the "dynamic" part. The EM finds the basin; a Gauss-Newton polish on the
// likelihood of each point lying on the other cloud's surface (sensor noise along the local
// normal) makes the fine fit, and the same likelihood chooses among starts turned about the
// vertical (heading_search_deg), which a rounded bush seen from two sides needs.
//
// The baselines go through the same API: Open3D's ICP (point-to-point, point-to-plane) and
// generalized ICP, coarse to fine from the target's RMS radius down to 3 point spacings.
#include <Eigen/Geometry>
#include <stdexcept>
#include <string>
#include <vector>

#include "trimbot/perception/point_cloud.h"

namespace trimbot::perception {

enum class RegistrationMethod { kDugma, kIcpPointToPoint, kIcpPointToPlane, kGeneralizedIcp };

struct RegistrationOptions {
  RegistrationMethod method = RegistrationMethod::kDugma;
  int max_iterations = 100;
  // rad + m: the polish stops, converged, when a step moves less than this (1e-3: 0.06 deg, 1 mm,
  // well under the errors that matter; its steps do not shrink much below it)
  double tolerance = 1e-3;
  int neighbours = 10;  // k nearest target points per source point
  // The EM uses at most this many source points (0: all): it only has to find the basin, the
  // polish and the fit use up to 2000 of the full cloud.
  int max_source_points = 500;
  double truncation_sigmas = 3.0;  // pairs farther apart (Mahalanobis) are left out
  double outlier_weight = 0.1;     // relative weight of the outlier term in the E-step
  // Annealing: initial extra spread (m); < 0 picks it from the initial misalignment (the median
  // distance of the source points to their nearest target point) and the size of the target
  // (30 % of its RMS radius), whichever is larger.
  double anneal_start = -1.0;
  double anneal_factor = 0.9;  // per iteration
  // Covariances given as relative weights (as in the DUGMA Kinect data set) are scaled so that
  // each cloud's median point variance equals the square of its own median point spacing.
  bool relative_covariances = false;
  // Surface patches (DUGMA): two clouds sample a surface at different places, so their points do
  // not correspond one to one and only the distance across the surface is evidence. Each point's
  // covariance keeps its variance along the local normal (from its 10 nearest neighbours in its
  // own cloud) and gets a standard deviation of `surface_spacings` point spacings along the surface
  // (as generalized ICP's plane-to-plane term). Off by default: normals from 10 noisy neighbours
  // are ~10 deg off, which leaks the in-plane spread across the surface, and with the heading
  // starts and the polish it did worse (rendered set 41/50 under 5 deg against 48/50, shared
  // pairs 14/15 against 15/15). Kept for the cross-validation grid. 0 keeps the covariances as given.
  double surface_spacings = 0.0;
  // Starts about the vertical (DUGMA): how far the guess's heading may be off. A rounded bush seen
  // from two sides also fits turned by the angle between the views, and annealing from one start
  // settles there. With heading_search_deg >= heading_step_deg the EM also starts turned by 0,
  // +-1, ... steps within +-heading_search_deg about the normal of the target's dominant plane (in
  // a garden the ground: the vertical, which the robot's IMU knows) and keeps the result that lies
  // best on the surfaces (RegistrationResult::surface_log_likelihood). 0 trusts the guess's
  // heading (one start); no dominant plane (under 10 % of the points) also leaves one start.
  double heading_search_deg = 0.0;
  double heading_step_deg = 15.0;
  int polish_iterations = 10;  // Gauss-Newton steps of the fine fit after the EM
  double max_variance = 1e4;   // m^2 (or relative units); larger marks an unusable point
  // Register the pair both ways and call the result untrusted when the two disagree by more than
  // max_inconsistency_deg (twice the time). If both were within 5 deg of the truth they would
  // differ by at most 10: more means at least one is off by more than 5 deg (the success bound).
  bool check_consistency = false;
  double max_inconsistency_deg = 10.0;
};

// One start of DUGMA and where it ended.
struct RegistrationStart {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  double on_surface = 0.0, log_likelihood = 0.0;
};

struct RegistrationResult {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // x = transform * y
  int iterations = 0;             // EM iterations (DUGMA); the stages' budget (ICP: Open3D reports no count)
  bool converged = false;         // DUGMA: the polish's last step moved less than the tolerance
  double final_cost = 0.0;        // weighted mean squared Mahalanobis distance of the pairs
  int pairs = 0;                  // pairs with weight in the last E-step
  double matched_fraction = 0.0;  // of the source points, those with a pair in the last E-step (DUGMA)
  // DUGMA: how well the clouds lie on each other's surface (both ways, averaged over up to 2000
  // points each): the fraction within 3 sigma of the sensors' noise, and the mean log-likelihood
  // ratio of on-surface against outlier, which chooses among the starts.
  double on_surface = 0.0;
  double surface_log_likelihood = 0.0;
  std::vector<RegistrationStart> starts;  // the guess first, then the heading starts
  int chosen_start = 0;
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
