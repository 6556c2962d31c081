#include "trimbot/perception/topiary_fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace trimbot::perception {
namespace {

// Radial distance of a point to a superellipsoid, for Ceres: parameters are the centre (3), yaw
// (1) and the semi-axes (3, some tied by the caller through `axes`).
template <typename T>
T Radial(const Eigen::Vector3d& point, double n, double m, const T* centre, const T* yaw, const T* a, const T* b,
         const T* c) {
  using std::abs;
  using std::cos;
  using std::pow;
  using std::sin;
  using std::sqrt;
  const T dx = T(point.x()) - centre[0], dy = T(point.y()) - centre[1], dz = T(point.z()) - centre[2];
  const T x = cos(yaw[0]) * dx + sin(yaw[0]) * dy, y = -sin(yaw[0]) * dx + cos(yaw[0]) * dy;
  const T length = sqrt(x * x + y * y + dz * dz + T(1e-18));
  // The surface's radius along the unit direction (x, y, dz) / length.
  const T ux = abs(x / length) / a[0], uy = abs(y / length) / b[0], uz = abs(dz / length) / c[0];
  const T horizontal = pow(pow(ux + T(1e-12), n) + pow(uy + T(1e-12), n), m / n);
  const T radius = T(1.0) / pow(horizontal + pow(uz + T(1e-12), m), 1.0 / m);
  return length - radius;
}

struct WeightedRadial {
  Eigen::Vector3d point;
  double n, m, weight;
  AxesTied tied;
  std::optional<double> base_height;  // the centre's height is then base + c (its own is held)
  template <typename T>
  bool operator()(const T* centre, const T* yaw, const T* axes, T* residual) const {
    const T* a = axes;
    const T* b = tied == AxesTied::kNone ? axes + 1 : axes;
    const T* c = tied == AxesTied::kAll ? axes : (tied == AxesTied::kHorizontal ? axes + 1 : axes + 2);
    const T standing[3] = {centre[0], centre[1], base_height ? T(*base_height) + c[0] : centre[2]};
    residual[0] = T(weight) * Radial(point, n, m, standing, yaw, a, b, c);
    return true;
  }
};

int FreeAxes(AxesTied tied) { return tied == AxesTied::kAll ? 1 : (tied == AxesTied::kHorizontal ? 2 : 3); }

// The semi-axes are one parameter block of as many values as are free.
ceres::CostFunction* MakeCost(const WeightedRadial& residual) {
  switch (FreeAxes(residual.tied)) {
    case 1:
      return new ceres::AutoDiffCostFunction<WeightedRadial, 1, 3, 1, 1>(new WeightedRadial(residual));
    case 2:
      return new ceres::AutoDiffCostFunction<WeightedRadial, 1, 3, 1, 2>(new WeightedRadial(residual));
    default:
      return new ceres::AutoDiffCostFunction<WeightedRadial, 1, 3, 1, 3>(new WeightedRadial(residual));
  }
}

}  // namespace

double TopiaryShape::RadialDistance(const Eigen::Vector3d& point) const {
  return Radial(point, horizontal_exponent, vertical_exponent, centre.data(), &yaw, &half.x(), &half.y(), &half.z());
}

std::optional<TopiaryFit> FitTopiary(const std::vector<Eigen::Vector3d>& points, const TopiaryShape& initial,
                                     AxesTied tied, const TopiaryFitOptions& options, std::string* failure) {
  const auto fail = [&](const std::string& why) -> std::optional<TopiaryFit> {
    if (failure) *failure = why;
    return std::nullopt;
  };
  if (static_cast<int>(points.size()) < options.min_points)
    return fail("topiary fit: " + std::to_string(points.size()) + " points, " + std::to_string(options.min_points) +
                " needed");
  TopiaryShape shape = initial;
  double axes[3] = {shape.half.x(), shape.half.y(), shape.half.z()};
  if (tied == AxesTied::kAll) axes[0] = shape.half.mean();
  if (tied == AxesTied::kHorizontal) {
    axes[0] = 0.5 * (shape.half.x() + shape.half.y());
    axes[1] = shape.half.z();
  }
  std::vector<double> residuals(points.size(), 0.0);
  const auto update_residuals = [&] {
    shape.half = tied == AxesTied::kAll          ? Eigen::Vector3d::Constant(axes[0])
                 : tied == AxesTied::kHorizontal ? Eigen::Vector3d(axes[0], axes[0], axes[1])
                                                 : Eigen::Vector3d(axes[0], axes[1], axes[2]);
    if (options.base_height) shape.centre.z() = *options.base_height + shape.half.z();
    for (std::size_t i = 0; i < points.size(); ++i) residuals[i] = shape.RadialDistance(points[i]);
  };
  update_residuals();
  // Quantile regression as reweighted least squares: the pinball loss tau r (r > 0) or
  // (1 - tau) |r| (r < 0) equals a squared residual weighted by that factor over |r|.
  for (int iteration = 0; iteration < options.reweightings; ++iteration) {
    ceres::Problem problem;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double factor = residuals[i] > 0.0 ? options.quantile : 1.0 - options.quantile;
      const double weight = std::sqrt(factor / std::max(std::abs(residuals[i]), options.residual_floor));
      problem.AddResidualBlock(MakeCost(WeightedRadial{points[i], shape.horizontal_exponent, shape.vertical_exponent,
                                                       weight, tied, options.base_height}),
                               nullptr, shape.centre.data(), &shape.yaw, axes);
    }
    if (options.base_height) problem.SetManifold(shape.centre.data(), new ceres::SubsetManifold(3, {2}));
    for (int k = 0; k < FreeAxes(tied); ++k) problem.SetParameterLowerBound(axes, k, 0.02);
    ceres::Solver::Options solver;
    solver.max_num_iterations = 50;
    solver.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    if (summary.termination_type == ceres::FAILURE) return fail("topiary fit: " + summary.message);
    update_residuals();
  }
  TopiaryFit fit;
  fit.shape = shape;
  fit.points = static_cast<int>(points.size());
  int inside = 0;
  for (double r : residuals) {
    inside += r < 0.0 ? 1 : 0;
    fit.loss += r > 0.0 ? options.quantile * r : (options.quantile - 1.0) * r;
  }
  fit.inside_share = static_cast<double>(inside) / static_cast<double>(points.size());
  fit.loss /= static_cast<double>(points.size());
  return fit;
}

}  // namespace trimbot::perception
