#include "trimbot/common/rotation.h"
#include "trimbot/perception/registration.h"

#include "open3d_icp.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <nanoflann.hpp>

#include <algorithm>
#include <sstream>
#include <cmath>
#include <deque>
#include <memory>
#include <unordered_map>
#include <vector>

namespace trimbot::perception {
namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// nanoflann adaptor over a vector of points.
struct PointsAdaptor {
  const std::vector<Eigen::Vector3d>& points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const { return points[i][static_cast<int>(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>, PointsAdaptor, 3,
                                                   std::uint32_t>;

// The target at one resolution: while the annealing spread is wide, the E-step meets a coarser
// version of the target, so its k nearest points still cover a few spreads (a fixed k on the full
// cloud would see only a few centimetres around each point and lose the wide basin).
struct TargetLevel {
  double voxel = 0.0;  // m, 0 for the full cloud
  PointCloud cloud;
  std::unique_ptr<PointsAdaptor> adaptor;
  std::unique_ptr<KdTree> tree;

  void Build() {
    adaptor = std::make_unique<PointsAdaptor>(PointsAdaptor{cloud.points});
    tree = std::make_unique<KdTree>(3, *adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
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

// argmin over R, t of sum_j w_j |xbar_j - R y_j - t|^2 with xbar_j = weighted_target_j / w_j.
Eigen::Isometry3d WeightedKabsch(const std::vector<SourceTerms>& terms, const std::vector<Eigen::Vector3d>& y) {
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
double MedianSpacing(const PointCloud& cloud, const KdTree& tree) {
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

// Each point's covariance as a surface patch: its variance across the local plane (the normal of
// its 10 nearest neighbours) kept, `along` standard deviation within the plane.
void SurfaceCovariances(double along, PointCloud* cloud) {
  TargetLevel level;
  level.cloud = *cloud;
  level.Build();
  const Eigen::Matrix3d in_plane_unit = Eigen::Matrix3d::Identity();
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    std::uint32_t index[10];
    double d2[10];
    const std::size_t found = level.tree->knnSearch(cloud->points[i].data(), 10, index, d2);
    if (found < 3) continue;  // no plane to speak of: the covariance stays as given
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t n = 0; n < found; ++n) mean += cloud->points[index[n]];
    mean /= static_cast<double>(found);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (std::size_t n = 0; n < found; ++n) {
      const Eigen::Vector3d d = cloud->points[index[n]] - mean;
      scatter += d * d.transpose();
    }
    const Eigen::Vector3d normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
    const Eigen::Matrix3d across = normal * normal.transpose();
    cloud->covariances[i] = along * along * (in_plane_unit - across) + normal.dot(cloud->covariances[i] * normal) * across;
  }
}

// The clouds as registration uses them: cleaned, covariances scaled, and a pyramid of voxel
// levels of the target (with a k-d tree each) and of the source.
struct Prepared {
  PointCloud target, source;
  double point_spacing = 0.0;           // median nearest-neighbour distance in the target
  bool isotropic = true;                // every covariance is c I
  double typical_target_variance = 0.0;
  std::deque<TargetLevel> levels;       // a deque: growing it never moves a level its tree points into
  std::vector<PointCloud> source_levels;
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
  const KdTree& tree = *p->levels[0].tree;

  // Median spacing of the target (nearest other point), the scale of "close".
  p->point_spacing = MedianSpacing(target, tree);

  TargetLevel source_level;
  source_level.cloud = source;
  source_level.Build();
  const double source_spacing = MedianSpacing(source, *source_level.tree);
  if (options.relative_covariances) {
    // Relative weights become variances with each cloud's own density: a sparse cloud's points
    // stand for more surface than a dense one's (with the target's scale for both, a target thinned
    // to ~500 points left the median error at 2.0 deg on the shared pairs).
    ScaleRelativeCovariances(p->point_spacing, &target);
    ScaleRelativeCovariances(source_spacing, &source);
  }
  if (options.method == RegistrationMethod::kDugma && options.surface_spacings > 0.0) {
    SurfaceCovariances(options.surface_spacings * p->point_spacing, &target);
    SurfaceCovariances(options.surface_spacings * source_spacing, &source);
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
double RmsRadius(const PointCloud& cloud) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& point : cloud.points) centroid += point;
  centroid /= static_cast<double>(cloud.size());
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
        const Eigen::Matrix3d C = level.cloud.covariances[index[n]] + source_cov + spread2 * Eigen::Matrix3d::Identity();
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
// isotropic, else one Gauss-Newton step on SE(3)).
Eigen::Isometry3d MStep(const std::vector<SourceTerms>& terms, const PointCloud& moving, const Eigen::Isometry3d& T,
                        bool closed_form, int pairs) {
  if (closed_form) return WeightedKabsch(terms, moving.points);
  Eigen::Isometry3d next = T;
  Matrix6 H = Matrix6::Zero();
  Vector6 g = Vector6::Zero();
  for (const auto& term : terms) {
    H += term.H;
    g += term.g;
  }
  if (pairs > 0) {
    const Vector6 delta = -(H + 1e-9 * Matrix6::Identity()).ldlt().solve(g);
    if (delta.allFinite()) {
      next.linear() = RotationFromVector(delta.head<3>()) * T.linear();
      next.translation() = T.translation() + delta.tail<3>();
    }
  }
  return next;
}

}  // namespace

namespace {
RegistrationResult RegisterOnce(const PointCloud& target_in, const PointCloud& source_in, const Eigen::Isometry3d& initial,
                                const RegistrationOptions& options);
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

RegistrationResult RegisterOnce(const PointCloud& target_in, const PointCloud& source_in, const Eigen::Isometry3d& initial,
                                const RegistrationOptions& options) {
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
  double anneal = options.anneal_start < 0.0 ? InitialSpread(p, T) : options.anneal_start;
  std::vector<SourceTerms> terms(p.source.size());

  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    // The coarsest target whose voxels are no wider than the spread.
    std::size_t level_index = 0;
    while (level_index + 1 < p.levels.size() && p.levels[level_index + 1].voxel <= anneal) ++level_index;
    const PointCloud& moving = p.source_levels[level_index];
    const EStep e{p.levels[level_index], moving, T.linear(), T.translation(), p.isotropic,
                  std::max(1, options.neighbours), 2.0 * anneal * anneal,
                  options.truncation_sigmas * options.truncation_sigmas, p.typical_target_variance, options.outlier_weight};
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
    const Eigen::Isometry3d next = MStep(terms, moving, T, p.isotropic, pairs);
    result.iterations = iteration + 1;
    if (pairs == 0 || !next.matrix().allFinite()) break;  // nothing matched: keep the last transform
    const double step = std::acos(std::clamp(((next.linear().transpose() * T.linear()).trace() - 1.0) / 2.0, -1.0, 1.0)) +
                        (next.translation() - T.translation()).norm();
    T = next;
    result.final_cost = matched > 0 ? cost / matched : 0.0;
    result.pairs = pairs;
    result.matched_fraction = static_cast<double>(matched) / static_cast<double>(std::max<std::size_t>(1, moving.size()));
    if (step < options.tolerance && anneal == 0.0) {
      result.converged = true;
      break;
    }
    anneal *= options.anneal_factor;
    if (anneal < 0.5 * p.point_spacing) anneal = 0.0;  // below the point spacing the points' own covariances rule
  }
  // Re-orthonormalize against accumulated rounding.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(T.linear(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  T.linear() = svd.matrixU() * svd.matrixV().transpose();
  result.transform = T;
  return result;
}

}  // namespace

}  // namespace trimbot::perception
