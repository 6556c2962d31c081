#pragma once
// A topiary's target shape from its leaf points. Topiary shapes are superellipsoids
// (|x/a|^n + |y/b|^n)^(m/n) + |z/c|^m = 1: a ball or ellipsoid (n = m = 2), a cylinder with
// rounded rims (n = 2, m large), a box with rounded edges (n = m large); the exponents come with the
// garden plan's shape, the fit finds the centre, yaw and semi-axes. A bush due for trimming is the
// target plus a season's shoots, so a least-squares fit would land on the shoots. This one sits at
// a low quantile of the points' radial distances to the surface (quantile regression by
// iteratively reweighted least squares, Ceres): the canopy the last trim left, with the shoots
// outside it. It fits the shape into the bush, as the TrimBot's own shape fitting did (Kaljaca et
// al., IROS 2020).
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace trimbot::perception {

struct TopiaryShape {
  double horizontal_exponent = 2.0;                        // n
  double vertical_exponent = 2.0;                          // m
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();        // m, in the points' frame (z up)
  double yaw = 0.0;                                        // rad about z
  Eigen::Vector3d half = Eigen::Vector3d::Constant(0.35);  // m: semi-axes a, b, c

  // Signed distance from the surface along the ray from the centre through `point` (outside > 0).
  double RadialDistance(const Eigen::Vector3d& point) const;
  // Distance from the centre to the surface along a unit direction (a point 1 m out along it lies
  // 1 m - radius outside).
  double Radius(const Eigen::Vector3d& direction) const { return 1.0 - RadialDistance(centre + direction); }
};

// Which semi-axes are tied: a ball's three, a round cylinder's or ellipsoid's two horizontal ones.
enum class AxesTied { kAll, kHorizontal, kNone };

struct TopiaryFitOptions {
  // Share of the points the fitted surface leaves inside it. Well under the share of a due bush's
  // surface that lies at its target (27 % within 2 cm before trimming, van Marrewijk et al.,
  // Biosystems Engineering 214, 2022), so the fit lands on that part of the canopy.
  double quantile = 0.1;
  int reweightings = 12;          // iterations of the reweighted least squares
  double residual_floor = 0.002;  // m: residuals are weighted as at least this (IRLS's epsilon)
  int min_points = 50;
  // m, in the points' frame: where the target's bottom stands, when the garden plan says (a
  // topiary's foliage starts at its base, on the ground). The foot is hidden in the grass, so
  // without it the height and the vertical semi-axis trade off against each other: a box's fitted
  // bottom wanders by a decimetre. Unset: the centre's height is fitted freely.
  std::optional<double> base_height;
};

struct TopiaryFit {
  TopiaryShape shape;
  int points = 0;
  double inside_share = 0.0;  // of the points, inside the fitted surface (close to the quantile)
  double loss = 0.0;          // mean pinball loss of the radial distances, m
};

// Fits `initial`'s exponents to `points` starting from its centre, yaw and semi-axes (from the
// garden plan or a coarser estimate). nullopt with the reason in *failure when there are fewer than
// min_points or the fit does not converge.
std::optional<TopiaryFit> FitTopiary(const std::vector<Eigen::Vector3d>& points, const TopiaryShape& initial,
                                     AxesTied tied, const TopiaryFitOptions& options = {},
                                     std::string* failure = nullptr);

}  // namespace trimbot::perception
