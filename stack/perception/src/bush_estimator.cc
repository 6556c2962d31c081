#include "trimbot/perception/bush_estimator.h"

#include <ceres/ceres.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

namespace trimbot::perception {

double BushShape::StandoffRadius(double bearing) const {
  if (kind == Kind::kBox) return Radius();
  const double a = 0.5 * size.x(), b = 0.5 * size.y();
  const double c = std::cos(bearing - yaw) / a, s = std::sin(bearing - yaw) / b;
  return 1.0 / std::sqrt(c * c + s * s);
}

namespace {

// A point of the bush: horizontal position in the fit's frame and height above the ground.
struct BushPoint {
  double x = 0.0, y = 0.0, height = 0.0;
};

// Signed distance (m) from a point to the shape scaled by s and centred at c. Ellipsoid and
// cylinder: approximate, the implicit function u (1 on the surface) over its gradient's length
// (Sampson); box: exact.
struct BushSurfaceResidual {
  BushSurfaceResidual(const BushPoint& point, const BushShape& shape) : point(point), shape(shape) {}

  template <typename T>
  bool operator()(const T* centre, const T* scale, T* residual) const {
    using std::abs;
    using std::fmax;
    using std::fmin;
    using std::sqrt;
    const T dx = T(point.x) - centre[0], dy = T(point.y) - centre[1];
    const double c = std::cos(shape.yaw), s = std::sin(shape.yaw);
    const T x = c * dx + s * dy, y = -s * dx + c * dy;
    if (shape.kind == BushShape::Kind::kBox) {
      // Signed distance to the box (outside: Euclidean; inside: to the nearest face).
      const T qx = abs(x) - scale[0] * (0.5 * shape.size.x()), qy = abs(y) - scale[0] * (0.5 * shape.size.y());
      const T qz = abs(T(point.height) - T(shape.base_height) - scale[0] * (0.5 * shape.size.z())) -
                   scale[0] * (0.5 * shape.size.z());
      const T ox = fmax(qx, T(0.0)), oy = fmax(qy, T(0.0)), oz = fmax(qz, T(0.0));
      const T outside = ox * ox + oy * oy + oz * oz;
      residual[0] = outside > T(1e-12) ? sqrt(outside) : fmin(fmax(qx, fmax(qy, qz)), T(0.0));
      return true;
    }
    const T a = scale[0] * (0.5 * shape.size.x()), b = scale[0] * (0.5 * shape.size.y());
    T u2 = (x / a) * (x / a) + (y / b) * (y / b);
    T g2 = (x / (a * a)) * (x / (a * a)) + (y / (b * b)) * (y / (b * b));
    if (shape.kind == BushShape::Kind::kEllipsoid) {
      const T half_height = scale[0] * (0.5 * shape.size.z());
      const T z = T(point.height) - (T(shape.base_height) + half_height);
      u2 += (z / half_height) * (z / half_height);
      g2 += (z / (half_height * half_height)) * (z / (half_height * half_height));
    }
    // d(sqrt(u2))/dp = grad / sqrt(u2), so (sqrt(u2) - 1) / |that| = (u2 - sqrt(u2)) / sqrt(g2).
    const T u = sqrt(u2 + T(1e-12));
    residual[0] = (u2 - u) / sqrt(g2 + T(1e-12));
    return true;
  }

  BushPoint point;
  BushShape shape;
};

struct ScalePrior {
  explicit ScalePrior(double weight) : weight(weight) {}
  template <typename T>
  bool operator()(const T* scale, T* residual) const {
    residual[0] = T(weight) * (scale[0] - T(1.0));
    return true;
  }
  double weight;
};

double Residual(const BushPoint& point, const BushShape& shape, const Eigen::Vector2d& centre, double scale) {
  double r = 0.0;
  BushSurfaceResidual(point, shape)(centre.data(), &scale, &r);
  return r;
}

// Solves for centre and scale from their current values; false if Ceres gives no usable solution.
bool Solve(const std::vector<BushPoint>& points, const BushShape& shape, const BushFitOptions& options, bool fit_scale,
           Eigen::Vector2d* centre, double* scale) {
  ceres::Problem problem;
  for (const BushPoint& point : points) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<BushSurfaceResidual, 1, 2, 1>(new BushSurfaceResidual(point, shape)),
        new ceres::HuberLoss(options.huber), centre->data(), scale);
  }
  if (fit_scale) {
    // The surveyed size weighs as much as the points: stereo's errors are correlated over a
    // bush's surface, so its points tell the size less well than their number suggests.
    const double weight = options.huber / options.scale_sigma * std::sqrt(static_cast<double>(points.size()));
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ScalePrior, 1, 1>(new ScalePrior(weight)), nullptr, scale);
    problem.SetParameterLowerBound(scale, 0, options.min_scale);
    problem.SetParameterUpperBound(scale, 0, options.max_scale);
  } else {
    problem.SetParameterBlockConstant(scale);
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = 50;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  return summary.IsSolutionUsable() && centre->allFinite() && std::isfinite(*scale);
}

// The gated points of the one foliage blob that is the bush: points are binned on a horizontal
// grid, and of the grid's 8-connected components the one with the most points within the
// expected outline is kept (a neighbour's foliage is another blob unless the two touch).
std::vector<BushPoint> BushBlob(const std::vector<BushPoint>& points, const Eigen::Vector2d& expected_centre,
                                double reach, double radius, double cell) {
  const int side = static_cast<int>(std::ceil(2.0 * reach / cell)) + 1;
  const auto bin = [&](const BushPoint& p) {
    return cv::Point(std::clamp(static_cast<int>((p.x - expected_centre.x() + reach) / cell), 0, side - 1),
                     std::clamp(static_cast<int>((p.y - expected_centre.y() + reach) / cell), 0, side - 1));
  };
  cv::Mat occupied = cv::Mat::zeros(side, side, CV_8U);
  for (const BushPoint& p : points) occupied.at<std::uint8_t>(bin(p)) = 255;
  cv::Mat labels;
  const int count = cv::connectedComponents(occupied, labels, 8, CV_32S);
  std::vector<int> votes(static_cast<std::size_t>(count), 0);
  for (const BushPoint& p : points) {
    if (std::hypot(p.x - expected_centre.x(), p.y - expected_centre.y()) <= radius) {
      ++votes[static_cast<std::size_t>(labels.at<int>(bin(p)))];
    }
  }
  const int best = static_cast<int>(std::max_element(votes.begin() + 1, votes.end()) - votes.begin());
  std::vector<BushPoint> blob;
  for (const BushPoint& p : points) {
    if (labels.at<int>(bin(p)) == best) blob.push_back(p);
  }
  return blob;
}

}  // namespace

std::optional<BushEstimate> FitBush(const PointCloud& cloud, const GroundPlane& ground, const BushShape& shape,
                                    const Eigen::Vector2d& expected_centre, const BushFitOptions& options,
                                    std::string* failure) {
  const auto fail = [&](const std::string& why) -> std::optional<BushEstimate> {
    if (failure != nullptr) *failure = why;
    return std::nullopt;
  };
  const double max_variance = options.max_position_sigma * options.max_position_sigma;
  const double reach = options.max_scale * shape.Radius() + options.gate;
  const double top = shape.base_height + options.max_scale * shape.size.z() + options.gate;
  std::vector<BushPoint> gated;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.points[i];
    if (cloud.covariances[i].trace() > max_variance) continue;
    const double height = ground.Distance(p);
    if (height < options.min_height || height > top) continue;
    if ((p.head<2>() - expected_centre).norm() > reach) continue;
    gated.push_back({p.x(), p.y(), height});
  }
  if (static_cast<int>(gated.size()) < options.min_points) {
    return fail(std::to_string(gated.size()) + " points near the expected bush (" + std::to_string(options.min_points) +
                " needed)");
  }
  gated = BushBlob(gated, expected_centre, reach, shape.Radius(), options.blob_cell);
  if (static_cast<int>(gated.size()) < options.min_points) {
    return fail("the foliage near the expected bush has " + std::to_string(gated.size()) + " points (" +
                std::to_string(options.min_points) + " needed)");
  }
  // Thinned evenly: neighbouring stereo points carry nearly the same information.
  const std::size_t stride = (gated.size() + options.max_points - 1) / options.max_points;
  std::vector<BushPoint> points;
  for (std::size_t i = 0; i < gated.size(); i += stride) points.push_back(gated[i]);

  Eigen::Vector2d centre = expected_centre;
  double scale = 1.0;
  // First at the surveyed size, so that a neighbour's foliage in the gate cannot swell the shape
  // to take it in; then, on the points near that surface, with the size free.
  if (!Solve(points, shape, options, false, &centre, &scale)) return fail("the shape fit did not converge");
  std::vector<BushPoint> near;
  for (const BushPoint& point : points) {
    if (std::abs(Residual(point, shape, centre, scale)) <= options.refit_gate) near.push_back(point);
  }
  if (static_cast<int>(near.size()) < options.min_points) {
    return fail(std::to_string(near.size()) + " points near the fitted bush (" + std::to_string(options.min_points) +
                " needed)");
  }
  if (!Solve(near, shape, options, true, &centre, &scale)) return fail("the shape fit did not converge");

  BushEstimate estimate;
  estimate.centre = centre;
  estimate.scale = scale;
  estimate.points = static_cast<int>(near.size());
  double sum = 0.0;
  int inliers = 0;
  for (const BushPoint& point : near) {
    const double r = Residual(point, shape, centre, scale);
    if (std::abs(r) > options.huber) continue;
    sum += r * r;
    ++inliers;
  }
  estimate.rms = inliers > 0 ? std::sqrt(sum / inliers) : 0.0;
  estimate.inlier_fraction = static_cast<double>(inliers) / static_cast<double>(near.size());
  return estimate;
}

}  // namespace trimbot::perception
