#include "trimbot/perception/registration.h"
#include "trimbot/common/points_kd_tree.h"
#include "trimbot/common/rotation.h"

#include "open3d_icp.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <unordered_map>
#include <vector>

namespace trimbot::perception {
namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// The target at one resolution: while the annealing spread is wide, the E-step meets a coarser
// version of the target, so its k nearest points still cover a few spreads (a fixed k on the full
// cloud would see only a few centimetres around each point and lose the wide basin).
struct TargetLevel {
  double voxel = 0.0;  // m, 0 for the full cloud
  PointCloud cloud;
  std::unique_ptr<PointsAdaptor> adaptor;
  std::unique_ptr<PointsKdTree> tree;

  void Build() {
    adaptor = std::make_unique<PointsAdaptor>(PointsAdaptor{cloud.points});
    tree = std::make_unique<PointsKdTree>(3, *adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tree->buildIndex();
  }
};

// One point per voxel (the first in input order, so the result is deterministic), its covariance
// widened by the voxel's own spread.
PointCloud VoxelDownsample(const PointCloud& cloud, double voxel) {
  std::unordered_map<std::int64_t, bool> taken;
  PointCloud out;
  const Eigen::Matrix3d widen = (voxel * voxel / 12.0) * Eigen::Matrix3d::Identity();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.points[i];
    const std::int64_t key = (static_cast<std::int64_t>(std::floor(p.x() / voxel)) & 0x1fffff) |
                             ((static_cast<std::int64_t>(std::floor(p.y() / voxel)) & 0x1fffff) << 21) |
                             ((static_cast<std::int64_t>(std::floor(p.z() / voxel)) & 0x1fffff) << 42);
    if (taken.emplace(key, true).second) out.Add(p, cloud.covariances[i] + widen);
  }
  return out;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

bool IsIsotropic(const Eigen::Matrix3d& c) {
  const double scale = c.trace() / 3.0;
  return (c - scale * Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-9 * std::max(scale, 1e-300);
}

// Per source point, what the E-step found: for the closed-form M-step the summed weight and the
// weighted sum of its targets; for the Gauss-Newton step its normal-equation terms.
struct SourceTerms {
  double weight = 0.0;
  Eigen::Vector3d weighted_target = Eigen::Vector3d::Zero();
  Matrix6 H = Matrix6::Zero();
  Vector6 g = Vector6::Zero();
  double cost = 0.0;
  int pairs = 0;
};

// argmin over R, t of sum_j w_j |xbar_j - R y_j - t|^2 with xbar_j = weighted_target_j / w_j; with
// `fixed_rotation` only t moves.
Eigen::Isometry3d WeightedKabsch(const std::vector<SourceTerms>& terms, const std::vector<Eigen::Vector3d>& y,
                                 const Eigen::Matrix3d* fixed_rotation = nullptr) {
  double total = 0.0;
  Eigen::Vector3d sum_x = Eigen::Vector3d::Zero(), sum_y = Eigen::Vector3d::Zero();
  for (std::size_t j = 0; j < y.size(); ++j) {
    total += terms[j].weight;
    sum_x += terms[j].weighted_target;
    sum_y += terms[j].weight * y[j];
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (total <= 0.0) return T;
  const Eigen::Vector3d mean_x = sum_x / total, mean_y = sum_y / total;
  if (fixed_rotation != nullptr) {
    T.linear() = *fixed_rotation;
    T.translation() = mean_x - T.linear() * mean_y;
    return T;
  }
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();  // sum w (y - mean_y)(x - mean_x)^T
  for (std::size_t j = 0; j < y.size(); ++j) {
    if (terms[j].weight <= 0.0) continue;
    cross += (y[j] - mean_y) * (terms[j].weighted_target - terms[j].weight * mean_x).transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  T.linear() = svd.matrixV() * d * svd.matrixU().transpose();
  T.translation() = mean_x - T.linear() * mean_y;
  return T;
}

}  // namespace

namespace {

// Median distance from a point to its nearest other point (of up to 2000 points spread over the cloud).
double MedianSpacing(const PointCloud& cloud, const PointsKdTree& tree) {
  std::vector<double> spacing;
  for (std::size_t i = 0; i < cloud.size(); i += std::max<std::size_t>(1, cloud.size() / 2000)) {
    std::uint32_t index[2];
    double d2[2];
    if (tree.knnSearch(cloud.points[i].data(), 2, index, d2) == 2) spacing.push_back(std::sqrt(d2[1]));
  }
  return std::max(Median(spacing), 1e-6);
}

// Covariances given as relative weights, scaled so that the median point variance is the squared
// point spacing.
void ScaleRelativeCovariances(double spacing, PointCloud* cloud) {
  std::vector<double> variances;
  for (const auto& c : cloud->covariances) variances.push_back(c.trace() / 3.0);
  const double scale = spacing * spacing / std::max(Median(variances), 1e-300);
  for (auto& c : cloud->covariances) c *= scale;
}

// Each point's local surface: the normal of its 10 nearest neighbours in its own cloud (zero where
// fewer than 3 were found) and the sensor's variance along it.
struct LocalSurface {
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> normal_variances;
};

LocalSurface SurfaceOf(const PointCloud& cloud, const PointsKdTree& tree) {
  LocalSurface surface;
  surface.normals.assign(cloud.size(), Eigen::Vector3d::Zero());
  surface.normal_variances.assign(cloud.size(), 0.0);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::uint32_t index[10];
    double d2[10];
    const std::size_t found = tree.knnSearch(cloud.points[i].data(), 10, index, d2);
    if (found < 3) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t n = 0; n < found; ++n) mean += cloud.points[index[n]];
    mean /= static_cast<double>(found);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (std::size_t n = 0; n < found; ++n) {
      const Eigen::Vector3d d = cloud.points[index[n]] - mean;
      scatter += d * d.transpose();
    }
    surface.normals[i] = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
    surface.normal_variances[i] = surface.normals[i].dot(cloud.covariances[i] * surface.normals[i]);
  }
  return surface;
}

// Each point's covariance as a surface patch: its variance across the local plane kept, `along`
// standard deviation within the plane. Points without a plane keep the covariance as given.
void SurfaceCovariances(double along, const LocalSurface& surface, PointCloud* cloud) {
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    const Eigen::Vector3d& normal = surface.normals[i];
    if (normal.isZero()) continue;
    const Eigen::Matrix3d across = normal * normal.transpose();
    cloud->covariances[i] =
        along * along * (Eigen::Matrix3d::Identity() - across) + surface.normal_variances[i] * across;
  }
}

// The clouds as registration uses them: cleaned, covariances scaled, and a pyramid of voxel
// levels of the target (with a k-d tree each) and of the source.
struct Prepared {
  PointCloud target, source;
  double point_spacing = 0.0;  // median nearest-neighbour distance in the target
  double source_spacing = 0.0;
  bool isotropic = true;  // every covariance is c I
  double typical_target_variance = 0.0;
  std::deque<TargetLevel> levels;  // a deque: growing it never moves a level its tree points into
  std::vector<PointCloud> source_levels;
  // The full source with its own tree, and both clouds' local surfaces with the sensor's variance
  // across them (before any surface patch): what FitBothWays judges a result by.
  TargetLevel source_full;
  LocalSurface target_surface, source_surface;
};

void Prepare(const PointCloud& target_in, const PointCloud& source_in, const RegistrationOptions& options,
             RegistrationResult* result, Prepared* p) {
  p->target = CleanCloud(target_in, options.max_variance, &result->target_points);
  p->source = CleanCloud(source_in, options.max_variance, &result->source_points);
  PointCloud& target = p->target;
  PointCloud& source = p->source;
  if (target.size() < 3 || source.size() < 3) {
    throw RegistrationError("registration: needs at least 3 usable points in each cloud (target " +
                            std::to_string(target.size()) + " of " + std::to_string(target_in.size()) + ", source " +
                            std::to_string(source.size()) + " of " + std::to_string(source_in.size()) + ")");
  }
  p->levels.resize(1);
  p->levels[0].cloud = target;
  p->levels[0].Build();
  const PointsKdTree& tree = *p->levels[0].tree;

  // Median spacing of the target (nearest other point), the scale of "close".
  p->point_spacing = MedianSpacing(target, tree);

  p->source_full.cloud = source;
  p->source_full.Build();
  p->source_spacing = MedianSpacing(source, *p->source_full.tree);
  if (options.relative_covariances) {
    // Relative weights become variances with each cloud's own density: a sparse cloud's points
    // stand for more surface than a dense one's (with the target's scale for both, a target thinned
    // to ~500 points left the median error at 2.0 deg on the shared pairs).
    ScaleRelativeCovariances(p->point_spacing, &target);
    ScaleRelativeCovariances(p->source_spacing, &source);
  }
  p->source_full.cloud.covariances = source.covariances;
  if (options.method != RegistrationMethod::kDugma) return;  // the baselines need only the target
  p->target_surface = SurfaceOf(target, tree);
  p->source_surface = SurfaceOf(source, *p->source_full.tree);
  if (options.surface_spacings > 0.0) {
    SurfaceCovariances(options.surface_spacings * p->point_spacing, p->target_surface, &target);
    SurfaceCovariances(options.surface_spacings * p->source_spacing, p->source_surface, &source);
  }
  for (const auto& c : target.covariances) p->isotropic = p->isotropic && IsIsotropic(c);
  for (const auto& c : source.covariances) p->isotropic = p->isotropic && IsIsotropic(c);
  std::vector<double> target_variances;
  for (const auto& c : target.covariances) target_variances.push_back(c.trace() / 3.0);
  p->typical_target_variance = Median(target_variances);

  p->levels[0].cloud.covariances = target.covariances;  // scaled above
  for (double voxel = 4.0 * p->point_spacing; voxel <= 1.0; voxel *= 2.0) {
    PointCloud coarse = VoxelDownsample(target, voxel);
    if (coarse.size() < 50) break;
    TargetLevel& level = p->levels.emplace_back();  // built in place: its tree refers to its points
    level.voxel = voxel;
    level.cloud = std::move(coarse);
    level.Build();
  }
  // The source at each level's resolution too: while the spread is wide, fewer source points
  // carry the same information, and the early iterations cost a fraction of the late ones.
  p->source_levels.resize(p->levels.size());
  p->source_levels[0] = source;
  if (options.max_source_points > 0 && source.size() > static_cast<std::size_t>(options.max_source_points)) {
    // Every k-th point: the target keeps its full density, which is what the accuracy rests on.
    const std::size_t stride = (source.size() + options.max_source_points - 1) / options.max_source_points;
    PointCloud thinned;
    for (std::size_t j = 0; j < source.size(); j += stride) thinned.Add(source.points[j], source.covariances[j]);
    p->source_levels[0] = std::move(thinned);
  }
  for (std::size_t l = 1; l < p->levels.size(); ++l) p->source_levels[l] = VoxelDownsample(source, p->levels[l].voxel);
}

// The RMS distance of the points from their centroid: the cloud's size.
Eigen::Vector3d Centroid(const PointCloud& cloud) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& point : cloud.points) sum += point;
  return sum / static_cast<double>(std::max<std::size_t>(1, cloud.size()));
}

double RmsRadius(const PointCloud& cloud) {
  const Eigen::Vector3d centroid = Centroid(cloud);
  double spread2 = 0.0;
  for (const auto& point : cloud.points) spread2 += (point - centroid).squaredNorm();
  return std::sqrt(spread2 / static_cast<double>(cloud.size()));
}

// The annealing spread to start from: the typical distance of the source (at the initial guess)
// to the target, and at least a fraction of the target's size.
double InitialSpread(const Prepared& p, const Eigen::Isometry3d& T) {
  std::vector<double> distances;
  for (std::size_t j = 0; j < p.source.size(); j += std::max<std::size_t>(1, p.source.size() / 2000)) {
    const Eigen::Vector3d y = T * p.source.points[j];
    std::uint32_t index;
    double d2;
    p.levels[0].tree->knnSearch(y.data(), 1, &index, &d2);
    distances.push_back(std::sqrt(d2));
  }
  // Points on a plane find near neighbours whatever the misalignment along it, so the spread
  // also starts at a fraction of the target's size.
  const double rms_radius = RmsRadius(p.target);
  return std::clamp(std::max(Median(distances), 0.3 * rms_radius), p.point_spacing, 1.0);
}

// What one E-step iteration needs to score one source point against a target level.
struct EStep {
  const TargetLevel& level;
  const PointCloud& moving;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  bool isotropic = true;
  int k = 1;
  double spread2 = 0.0, gate2 = 0.0, typical_target_variance = 0.0, outlier_weight = 0.0;

  // The pair terms of source point j (posterior weights of its k nearest target points).
  SourceTerms Terms(std::size_t j) const {
    SourceTerms term;
    const Eigen::Vector3d y = R * moving.points[j] + t;
    std::uint32_t index[64];
    double d2[64];
    const std::size_t found = level.tree->knnSearch(y.data(), static_cast<std::size_t>(std::min(k, 64)), index, d2);
    const Eigen::Matrix3d source_cov = R * moving.covariances[j] * R.transpose();
    // Outlier term: the density of a pair at the truncation distance with typical covariances.
    const Eigen::Matrix3d typical = source_cov + (typical_target_variance + spread2) * Eigen::Matrix3d::Identity();
    const double outlier = outlier_weight * std::exp(-0.5 * gate2) / std::sqrt(typical.determinant());
    double weights[64];
    Eigen::Matrix3d informations[64];
    double total = 0.0;
    for (std::size_t n = 0; n < found; ++n) {
      const Eigen::Vector3d d = level.cloud.points[index[n]] - y;
      double m = 0.0, determinant = 0.0;
      if (isotropic) {  // C = c I: no 3x3 inverse per pair
        const double c = level.cloud.covariances[index[n]](0, 0) + source_cov(0, 0) + spread2;
        informations[n] = Eigen::Matrix3d::Identity() / c;
        m = d.squaredNorm() / c;
        determinant = c * c * c;
      } else {
        const Eigen::Matrix3d C =
            level.cloud.covariances[index[n]] + source_cov + spread2 * Eigen::Matrix3d::Identity();
        informations[n] = C.inverse();
        m = d.dot(informations[n] * d);
        determinant = C.determinant();
      }
      weights[n] = m > gate2 ? 0.0 : std::exp(-0.5 * m) / std::sqrt(determinant);
      total += weights[n];
    }
    if (total <= 0.0) return term;
    Accumulate(j, y, index, found, weights, informations, total + outlier, &term);
    return term;
  }

  void Accumulate(std::size_t j, const Eigen::Vector3d& y, const std::uint32_t* index, std::size_t found,
                  const double* weights, const Eigen::Matrix3d* informations, double normalizer,
                  SourceTerms* term) const {
    Eigen::Matrix3d information_sum = Eigen::Matrix3d::Zero();
    Eigen::Vector3d weighted_residual = Eigen::Vector3d::Zero();
    for (std::size_t n = 0; n < found; ++n) {
      if (weights[n] <= 0.0) continue;
      const double w = weights[n] / normalizer;  // posterior of the pair
      const Eigen::Vector3d& x = level.cloud.points[index[n]];
      const Eigen::Vector3d r = x - y;
      term->cost += w * r.dot(informations[n] * r);
      ++term->pairs;
      if (isotropic) {
        const double omega = w * informations[n](0, 0);
        term->weight += omega;
        term->weighted_target += omega * x;
      } else {
        information_sum += w * informations[n];
        weighted_residual += w * informations[n] * r;
        term->weight += w;
      }
    }
    if (!isotropic && term->weight > 0.0) {
      // r(delta) = x - (exp(dtheta) R y_src + t + dt): J = [ [R y_src]x , -I ], the same for all
      // of this point's pairs, so their information sums before the 6x6 products.
      Eigen::Matrix<double, 3, 6> J;
      J.leftCols<3>() = Skew(R * moving.points[j]);
      J.rightCols<3>() = -Eigen::Matrix3d::Identity();
      term->H = J.transpose() * information_sum * J;
      term->g = J.transpose() * weighted_residual;
    }
  }
};

// M-step: the transform that best explains the pairs (weighted Kabsch when every covariance is
// isotropic, else one Gauss-Newton step on SE(3)); with `translation_only` the rotation stays.
Eigen::Isometry3d MStep(const std::vector<SourceTerms>& terms, const PointCloud& moving, const Eigen::Isometry3d& T,
                        bool closed_form, int pairs, bool translation_only) {
  Eigen::Isometry3d next = T;
  if (closed_form && translation_only) {
    const Eigen::Matrix3d rotation = T.linear();
    return WeightedKabsch(terms, moving.points, &rotation);
  }
  if (closed_form) return WeightedKabsch(terms, moving.points);
  Matrix6 H = Matrix6::Zero();
  Vector6 g = Vector6::Zero();
  for (const auto& term : terms) {
    H += term.H;
    g += term.g;
  }
  if (pairs == 0) return next;
  if (translation_only) {
    const Eigen::Vector3d delta =
        -(H.bottomRightCorner<3, 3>() + 1e-9 * Eigen::Matrix3d::Identity()).ldlt().solve(g.tail<3>());
    if (delta.allFinite()) next.translation() = T.translation() + delta;
    return next;
  }
  const Vector6 delta = -(H + 1e-9 * Matrix6::Identity()).ldlt().solve(g);
  if (delta.allFinite()) {
    next.linear() = RotationFromVector(delta.head<3>()) * T.linear();
    next.translation() = T.translation() + delta.tail<3>();
  }
  return next;
}

}  // namespace

namespace {

// DUGMA's EM from T, the annealing spread starting at `anneal` and shrinking until the points' own
// covariances rule: fills the result's transform and the EM's state (iterations, cost, pairs,
// matched fraction). While the spread is wider than `turn_below` only the translation moves (a
// heading start keeps its heading until the clouds overlap). The fine fit is PolishOnSurface's.
void RunEm(const Prepared& p, const RegistrationOptions& options, double anneal, Eigen::Isometry3d T, double turn_below,
           RegistrationResult* result) {
  std::vector<SourceTerms> terms;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    // The coarsest target whose voxels are no wider than the spread.
    std::size_t level_index = 0;
    while (level_index + 1 < p.levels.size() && p.levels[level_index + 1].voxel <= anneal) ++level_index;
    const PointCloud& moving = p.source_levels[level_index];
    const EStep e{p.levels[level_index],
                  moving,
                  T.linear(),
                  T.translation(),
                  p.isotropic,
                  std::max(1, options.neighbours),
                  2.0 * anneal * anneal,
                  options.truncation_sigmas * options.truncation_sigmas,
                  p.typical_target_variance,
                  options.outlier_weight};
    terms.resize(moving.size());
    // E-step, in parallel over source points; each writes only its own terms (deterministic).
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t j = 0; j < static_cast<std::ptrdiff_t>(moving.size()); ++j) {
      terms[static_cast<std::size_t>(j)] = e.Terms(static_cast<std::size_t>(j));
    }
    double cost = 0.0;
    int matched = 0;  // source points with at least one pair
    int pairs = 0;
    for (const auto& term : terms) {
      cost += term.cost;
      matched += term.weight > 0.0 ? 1 : 0;
      pairs += term.pairs;
    }
    const Eigen::Isometry3d next = MStep(terms, moving, T, p.isotropic, pairs, anneal > turn_below);
    result->iterations = iteration + 1;
    if (pairs == 0 || !next.matrix().allFinite()) break;  // nothing matched: keep the last transform
    T = next;
    result->final_cost = matched > 0 ? cost / matched : 0.0;
    result->pairs = pairs;
    result->matched_fraction =
        static_cast<double>(matched) / static_cast<double>(std::max<std::size_t>(1, moving.size()));
    if (anneal == 0.0) break;
    anneal *= options.anneal_factor;
    if (anneal < 0.5 * p.point_spacing) anneal = 0.0;  // below the point spacing the points' own covariances rule
  }
  result->transform = T;
}

// Up to this many points of a cloud judge and polish a result: enough for a mean over the
// surface, few enough that every heading start can afford it.
constexpr std::size_t kFitPoints = 2000;

// How well `from`'s points lie on `to`'s surface once moved by T. Each point is compared with its
// nearest point of `to` (within `reach`) along that point's normal, against both points'
// variances along it. A rounded bush seen from two sides also fits turned by the angle between
// the views, but only to within its leaf clumps (centimetres); the truth fits to the sensor's
// noise (millimetres), and this likelihood tells the two apart where a count of close points
// does not (rendered set: 48 of 50 pairs against 37 of 50).
// One point moved by T against `to`'s surface: its distance across the normal of its nearest point
// of `to`, the variance of that distance (both points' along the normal) and its Gaussian density.
// Nothing when no point of `to` lies within `reach` or that point has no normal.
struct SurfaceResidual {
  Eigen::Vector3d moved, normal;
  double across = 0.0, variance = 0.0, density = 0.0;
};

std::optional<SurfaceResidual> ResidualOnSurface(const Eigen::Vector3d& point, const Eigen::Matrix3d& covariance,
                                                 const TargetLevel& to, const LocalSurface& to_surface,
                                                 const Eigen::Isometry3d& T, double reach) {
  SurfaceResidual r;
  r.moved = T * point;
  std::uint32_t index;
  double d2;
  if (to.tree->knnSearch(r.moved.data(), 1, &index, &d2) != 1 || d2 > reach * reach) return std::nullopt;
  r.normal = to_surface.normals[index];
  if (r.normal.isZero()) return std::nullopt;
  const Eigen::Vector3d moved_normal = T.linear().transpose() * r.normal;
  r.variance = to_surface.normal_variances[index] + moved_normal.dot(covariance * moved_normal);
  r.across = r.normal.dot(r.moved - to.cloud.points[index]);
  r.density = std::exp(-0.5 * r.across * r.across / r.variance) / std::sqrt(2.0 * M_PI * r.variance);
  return r;
}

struct SurfaceFit {
  double on_surface = 0.0;      // fraction within 3 sigma
  double log_likelihood = 0.0;  // mean log of (Gaussian + outlier) / outlier, the outlier uniform over +-reach
};

SurfaceFit FitOnSurface(const PointCloud& from, const TargetLevel& to, const LocalSurface& to_surface,
                        const Eigen::Isometry3d& T, double reach) {
  const std::size_t stride = std::max<std::size_t>(1, from.size() / kFitPoints);
  const double outlier = 1.0 / (2.0 * reach);
  int on = 0, tried = 0;
  double log_likelihood = 0.0;
  for (std::size_t j = 0; j < from.size(); j += stride) {
    ++tried;
    const auto r = ResidualOnSurface(from.points[j], from.covariances[j], to, to_surface, T, reach);
    if (!r) continue;
    on += r->across * r->across <= 9.0 * r->variance ? 1 : 0;
    log_likelihood += std::log((r->density + outlier) / outlier);
  }
  SurfaceFit fit;
  if (tried > 0) fit = {static_cast<double>(on) / tried, log_likelihood / tried};
  return fit;
}

// Two points are neighbours on a surface within this distance.
double Reach(const Prepared& p) { return 2.0 * std::max(p.point_spacing, p.source_spacing); }

// FitOnSurface both ways (source onto target, target onto source), averaged.
SurfaceFit FitBothWays(const Prepared& p, const Eigen::Isometry3d& T) {
  const SurfaceFit a = FitOnSurface(p.source_full.cloud, p.levels[0], p.target_surface, T, Reach(p));
  const SurfaceFit b = FitOnSurface(p.levels[0].cloud, p.source_full, p.source_surface, T.inverse(), Reach(p));
  return {0.5 * (a.on_surface + b.on_surface), 0.5 * (a.log_likelihood + b.log_likelihood)};
}

// The fine fit: Gauss-Newton on FitOnSurface's likelihood of the source on the target, each point
// weighted by its posterior of lying on the surface, its nearest target point found again every
// step. The EM's annealed GMM finds the basin but creeps near the optimum (the sampling makes its
// last millimetres bumpy); this gets there in a few steps. (Damping the steps, Levenberg-Marquardt
// style, did worse: 47/50 and 44/50 on two rendered sets against 48/50 and 47/50.) Sets converged
// when the last step moved less than the tolerance: where the turn about a rounded bush's axis is
// nearly free, the steps keep swinging along it.
Eigen::Isometry3d PolishOnSurface(const Prepared& p, const RegistrationOptions& options, Eigen::Isometry3d T,
                                  bool* converged) {
  const double reach = Reach(p);
  const double outlier = 1.0 / (2.0 * reach);
  const PointCloud& from = p.source_full.cloud;
  const std::size_t stride = std::max<std::size_t>(1, from.size() / kFitPoints);
  *converged = false;
  for (int iteration = 0; iteration < options.polish_iterations; ++iteration) {
    Matrix6 H = Matrix6::Zero();
    Vector6 g = Vector6::Zero();
    for (std::size_t j = 0; j < from.size(); j += stride) {
      const auto r = ResidualOnSurface(from.points[j], from.covariances[j], p.levels[0], p.target_surface, T, reach);
      if (!r) continue;
      const double weight = r->density / (r->density + outlier) / r->variance;
      Vector6 J;  // d across / d (rotation vector, translation) of a left update
      J.head<3>() = r->moved.cross(r->normal);
      J.tail<3>() = r->normal;
      H += weight * J * J.transpose();
      g += weight * J * r->across;
    }
    const Vector6 delta = -(H + 1e-9 * Matrix6::Identity()).ldlt().solve(g);
    if (!delta.allFinite()) break;
    Eigen::Isometry3d update = Eigen::Isometry3d::Identity();
    update.linear() = RotationFromVector(delta.head<3>());
    update.translation() = delta.tail<3>();
    T = update * T;
    if (delta.norm() < options.tolerance) {
      *converged = true;
      break;
    }
  }
  // Re-orthonormalize against accumulated rounding.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(T.linear(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  T.linear() = svd.matrixU() * svd.matrixV().transpose();
  return T;
}

// The normal shared by the most target points (within 10 deg), as the mean of those normals: in a
// garden the ground's, the vertical the robot's IMU knows. Zero when no normal is shared by at
// least `min_support` of the points.
Eigen::Vector3d DominantNormal(const LocalSurface& surface, double min_support) {
  const double cos_tolerance = std::cos(10.0 * M_PI / 180.0);
  const std::size_t n = surface.normals.size();
  const std::size_t candidates = std::max<std::size_t>(1, n / 100);  // every k-th normal is a candidate
  const std::size_t sample = std::max<std::size_t>(1, n / 3000);     // and is tested on every k-th
  std::size_t best_support = 0;
  Eigen::Vector3d best = Eigen::Vector3d::Zero();
  for (std::size_t c = 0; c < n; c += candidates) {
    const Eigen::Vector3d& candidate = surface.normals[c];
    if (candidate.isZero()) continue;
    std::size_t support = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; i += sample) {
      const double cosine = candidate.dot(surface.normals[i]);
      if (std::abs(cosine) < cos_tolerance) continue;
      ++support;
      sum += cosine > 0.0 ? surface.normals[i] : Eigen::Vector3d(-surface.normals[i]);
    }
    if (support > best_support) best_support = support, best = sum.normalized();
  }
  const double sampled = static_cast<double>((n + sample - 1) / sample);
  return static_cast<double>(best_support) >= min_support * sampled ? best : Eigen::Vector3d::Zero();
}

// One DUGMA run from T (EM, then the polish), judged by its fit on the surfaces.
RegistrationStart RunStart(const Prepared& p, const RegistrationOptions& options, const Eigen::Isometry3d& T,
                           double anneal, double turn_below, RegistrationResult* state) {
  RunEm(p, options, anneal, T, turn_below, state);
  state->transform = PolishOnSurface(p, options, state->transform, &state->converged);
  const SurfaceFit fit = FitBothWays(p, state->transform);
  return {state->transform, fit.on_surface, fit.log_likelihood};
}

}  // namespace

namespace {
RegistrationResult RegisterOnce(const PointCloud& target_in, const PointCloud& source_in,
                                const Eigen::Isometry3d& initial, const RegistrationOptions& options);
}  // namespace

RegistrationResult Register(const PointCloud& target_in, const PointCloud& source_in, const Eigen::Isometry3d& initial,
                            const RegistrationOptions& options) {
  RegistrationResult result = RegisterOnce(target_in, source_in, initial, options);
  if (!options.check_consistency) return result;
  // The same pair the other way round, from the same guess: a wrong minimum rarely agrees with
  // itself both ways, a right one does to within the noise.
  RegistrationOptions reverse_options = options;
  reverse_options.check_consistency = false;
  const RegistrationResult reverse = RegisterOnce(source_in, target_in, initial.inverse(), reverse_options);
  const Eigen::Isometry3d loop = result.transform * reverse.transform;
  result.consistency_deg = Eigen::AngleAxisd(loop.linear()).angle() * 180.0 / M_PI;
  result.consistency_m = loop.translation().norm();
  if (result.consistency_deg > options.max_inconsistency_deg) {
    result.trusted = false;
    std::ostringstream why;
    why << "registered both ways, the results differ by " << result.consistency_deg << " deg";
    result.doubt = why.str();
  }
  return result;
}

namespace {

RegistrationResult RegisterOnce(const PointCloud& target_in, const PointCloud& source_in,
                                const Eigen::Isometry3d& initial, const RegistrationOptions& options) {
  if (!initial.matrix().allFinite()) throw RegistrationError("registration: the initial guess is not finite");
  RegistrationResult result;
  Prepared p;
  Prepare(target_in, source_in, options, &result, &p);
  Eigen::Isometry3d T = initial;
  if (options.method != RegistrationMethod::kDugma) {  // the baselines: Open3D's ICP variants
    RegistrationResult icp = Open3dIcp(p.target, p.source, T, options, RmsRadius(p.target), p.point_spacing);
    icp.target_points = result.target_points;
    icp.source_points = result.source_points;
    return icp;
  }
  // From the guess: annealed from the misalignment (or the given spread).
  const double anneal = options.anneal_start < 0.0 ? InitialSpread(p, T) : options.anneal_start;
  result.starts.push_back(RunStart(p, options, T, anneal, std::numeric_limits<double>::infinity(), &result));
  const int turns = static_cast<int>(std::floor(options.heading_search_deg / options.heading_step_deg + 1e-9));
  const Eigen::Vector3d vertical = turns > 0 ? DominantNormal(p.target_surface, 0.1) : Eigen::Vector3d::Zero();
  if (!vertical.isZero()) {
    // Starts turned about the vertical by 0, +-1, ... steps, the source's centroid on the target's.
    // Each finds its translation under a wide spread (30 % of the target's RMS radius, as
    // InitialSpread's floor) with the heading held, and turns freely once the spread is down to
    // what half a step moves the target's rim, so it settles in its own basin.
    const Eigen::Vector3d target_centroid = Centroid(p.target);
    const Eigen::Vector3d source_centroid = T * Centroid(p.source);
    const double step = options.heading_step_deg * M_PI / 180.0;
    const double rms_radius = RmsRadius(p.target);
    const double turn_below = std::max(p.point_spacing, rms_radius * step / 2.0);
    for (int k = 0; k <= 2 * turns; ++k) {
      const double turn = step * ((k + 1) / 2) * (k % 2 == 1 ? 1.0 : -1.0);
      Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
      start.linear() = Eigen::AngleAxisd(turn, vertical).toRotationMatrix();
      start.translation() = target_centroid - start.linear() * source_centroid;
      RegistrationResult state = result;
      result.starts.push_back(RunStart(p, options, start * T, 0.3 * rms_radius, turn_below, &state));
      if (result.starts.back().log_likelihood > result.starts[result.chosen_start].log_likelihood) {
        state.starts = std::move(result.starts);
        state.chosen_start = static_cast<int>(state.starts.size()) - 1;
        result = std::move(state);
      }
    }
  }
  result.on_surface = result.starts[result.chosen_start].on_surface;
  result.surface_log_likelihood = result.starts[result.chosen_start].log_likelihood;
  return result;
}

}  // namespace

}  // namespace trimbot::perception
