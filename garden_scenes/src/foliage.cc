#include "trimbot/garden/foliage.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "trimbot/common/atomic_file.h"
#include "trimbot/common/random.h"
#include "trimbot/garden/conditions.h"
#include "trimbot/garden/object_mesh.h"

namespace trimbot::garden {
namespace {

constexpr double kNoCut = std::numeric_limits<double>::infinity();

// The smallest s in [0, limit] where the ray s * d (from the origin) meets the disc of `radius`
// about the segment from -> to, the disc's normal `axis` fixed during the move: kNoCut if none. The
// blade severs what lies beyond that point only when it falls: when the disc's plane there
// separates it from the `root` the foliage grows from (a blade passing between the centre and the
// stem would fell the crown, which the radial columns cannot hold; such a crossing is not a cut).
double FirstCrossing(const Eigen::Vector3d& d, double limit, const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                     const Eigen::Vector3d& axis, double radius, const Eigen::Vector3d& root) {
  const Eigen::Vector3d move = to - from;
  const double d_axis = d.dot(axis), move_axis = move.dot(axis), from_axis = from.dot(axis);
  // The point s d is in the disc at time t when (s d - from - t move) . axis = 0 and its distance
  // from the disc's centre there is at most the radius.
  const auto inside_at = [&](double s, double t) { return (s * d - from - t * move).squaredNorm() <= radius * radius; };
  const auto falls = [&](double t) { return (root - from - t * move).dot(axis) * d_axis < 0.0; };
  if (std::abs(move_axis) < 1e-12) {
    // Moving in the disc's own plane: the ray crosses that plane once, at s = from.axis / d.axis;
    // it is cut there if that point lies within the radius of the centre's path.
    if (std::abs(d_axis) < 1e-12) return kNoCut;  // the column lies in the plane: grazed, not severed
    const double s = from_axis / d_axis;
    if (s < 0.0 || s > limit) return kNoCut;
    const Eigen::Vector3d q = s * d;
    const double t = move.squaredNorm() > 0.0 ? std::clamp((q - from).dot(move) / move.squaredNorm(), 0.0, 1.0) : 0.0;
    return inside_at(s, t) && falls(t) ? s : kNoCut;
  }
  // Otherwise the plane reaches s d at t(s) = (s d.axis - from.axis) / move.axis; the point is
  // inside when t(s) is in [0, 1] and |s d - from - t(s) move|^2 <= r^2, a quadratic in s.
  const double t0 = -from_axis / move_axis, t1 = d_axis / move_axis;  // t(s) = t0 + t1 s
  double lo = 0.0, hi = limit;
  if (std::abs(t1) < 1e-15) {
    if (t0 < 0.0 || t0 > 1.0) return kNoCut;
  } else {
    const double sa = (0.0 - t0) / t1, sb = (1.0 - t0) / t1;
    lo = std::max(lo, std::min(sa, sb));
    hi = std::min(hi, std::max(sa, sb));
  }
  if (lo > hi) return kNoCut;
  // |s (d - t1 move) - (from + t0 move)|^2 <= r^2
  const Eigen::Vector3d u = d - t1 * move, w = from + t0 * move;
  const double a = u.squaredNorm(), b = -2.0 * u.dot(w), c = w.squaredNorm() - radius * radius;
  double s_in, s_out;
  if (a < 1e-15) {
    if (c > 0.0) return kNoCut;
    s_in = lo;
    s_out = hi;
  } else {
    const double discriminant = b * b - 4.0 * a * c;
    if (discriminant < 0.0) return kNoCut;
    const double root = std::sqrt(discriminant);
    s_in = (-b - root) / (2.0 * a);
    s_out = (-b + root) / (2.0 * a);
  }
  const double first = std::max(lo, s_in);
  return first <= std::min(hi, s_out) && falls(t0 + t1 * first) ? first : kNoCut;
}

// The unit direction at the centre of cell (r, s) of a grid of rings x segments (polar x azimuth).
Eigen::Vector3d CellDirection(int r, int s, int rings, int segments) {
  const double polar = M_PI * (r + 0.5) / rings, azimuth = 2.0 * M_PI * (s + 0.5) / segments;
  return {std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth), std::cos(polar)};
}

// The solid angle of a cell of ring r.
double CellSolidAngle(int r, int rings, int segments) {
  return std::sin(M_PI * (r + 0.5) / rings) * (M_PI / rings) * (2.0 * M_PI / segments);
}

}  // namespace

double Superellipsoid::Radius(const Eigen::Vector3d& d) const {
  const double n = horizontal_exponent, m = vertical_exponent;
  const double horizontal =
      std::pow(std::pow(std::abs(d.x() / half.x()), n) + std::pow(std::abs(d.y() / half.y()), n), m / n);
  return 1.0 / std::pow(horizontal + std::pow(std::abs(d.z() / half.z()), m), 1.0 / m);
}

Eigen::Vector3d Superellipsoid::Normal(const Eigen::Vector3d& p) const {
  // Gradient of F = (|x/a|^n + |y/b|^n)^(m/n) + |z/c|^m.
  const double n = horizontal_exponent, m = vertical_exponent;
  const double ux = std::abs(p.x() / half.x()), uy = std::abs(p.y() / half.y()), uz = std::abs(p.z() / half.z());
  const double h = std::pow(ux, n) + std::pow(uy, n);
  const double outer = h > 0.0 ? m / n * std::pow(h, m / n - 1.0) : 0.0;
  Eigen::Vector3d g(outer * n * std::pow(ux, n - 1.0) / half.x() * (p.x() < 0.0 ? -1.0 : 1.0),
                    outer * n * std::pow(uy, n - 1.0) / half.y() * (p.y() < 0.0 ? -1.0 : 1.0),
                    m * std::pow(uz, m - 1.0) / half.z() * (p.z() < 0.0 ? -1.0 : 1.0));
  return g.norm() > 0.0 ? Eigen::Vector3d(g.normalized()) : Eigen::Vector3d::UnitZ();
}

double Superellipsoid::Volume() const {
  // By quadrature over directions: V = (1/3) integral of r(d)^3 over the sphere.
  constexpr int kRings = 180, kSegments = 360;
  double volume = 0.0;
  for (int r = 0; r < kRings; ++r) {
    for (int s = 0; s < kSegments; ++s)
      volume +=
          std::pow(Radius(CellDirection(r, s, kRings, kSegments)), 3) / 3.0 * CellSolidAngle(r, kRings, kSegments);
  }
  return volume;
}

Superellipsoid TargetShape(const GardenObject& object) {
  Superellipsoid shape;
  shape.half = object.size / 2.0;
  if (object.shape == Shape::kBox) shape.horizontal_exponent = shape.vertical_exponent = 6.0;
  if (object.shape == Shape::kCylinder) shape.vertical_exponent = 6.0;
  return shape;
}

FoliageGrowth::FoliageGrowth(const GardenObject& object, std::uint64_t appearance_seed, double growth)
    : target_(TargetShape(object)),
      seed_(StreamSeed(appearance_seed, "foliage/" + std::to_string(object.id))),
      clump_depth_(IsFoliage(object.object_class) ? (object.object_class == ObjectClass::kTree ? 0.12 : 0.025) : 0.0),
      // Leaf clumps: ~12 cm features on bushes, ~40 cm on tree crowns.
      clump_scale_(object.object_class == ObjectClass::kTree ? 0.4 : 0.12),
      growth_(IsFoliage(object.object_class) ? growth : 0.0) {}

double FoliageGrowth::Outgrowth(const Eigen::Vector3d& d) const {
  const Eigen::Vector3d surface = d * target_.Radius(d);
  const double clumps =
      ValueNoise(seed_, surface / clump_scale_) * 0.7 + ValueNoise(seed_ + 1, surface / (clump_scale_ * 0.4)) * 0.3;
  // Outgrowth in patches of ~30 cm shoots.
  const double shoots = std::max(0.0, ValueNoise(seed_ + 2, surface / 0.3));
  return clump_depth_ * clumps + growth_ * kMaxGrowth * (0.4 + 1.2 * shoots);
}

Eigen::Vector3d FoliageGrowth::SurfacePoint(const Eigen::Vector3d& d) const {
  const Eigen::Vector3d surface = d * target_.Radius(d);
  return surface + target_.Normal(surface) * Outgrowth(d);
}

Foliage Foliage::Grown(const GardenObject& object, std::uint64_t appearance_seed, double growth, int rings,
                       int segments) {
  const FoliageGrowth grown(object, appearance_seed, growth);
  Foliage foliage;
  foliage.target_ = grown.target();
  foliage.rings_ = rings;
  foliage.segments_ = segments;
  const Eigen::Matrix4d T = ObjectPose(object);
  foliage.T_map_centre_.matrix() = T;
  foliage.T_map_centre_.translate(Eigen::Vector3d(0.0, 0.0, foliage.target_.half.z()));
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const Eigen::Vector3d d = CellDirection(r, s, rings, segments);
      const Eigen::Vector3d root = foliage.target_.Radius(d) * d, normal = foliage.target_.Normal(root);
      // Never below the shape's bottom (it sits on the ground or its stem).
      const double floor = normal.z() < 0.0 ? (root.z() + foliage.target_.half.z()) / -normal.z() : kNoCut;
      foliage.direction_.push_back(d);
      foliage.solid_angle_.push_back(CellSolidAngle(r, rings, segments));
      foliage.root_.push_back(root);
      foliage.normal_.push_back(normal);
      foliage.height_.push_back(std::min(grown.Outgrowth(d), floor));
      foliage.floor_height_.push_back(floor);
      foliage.reach_ = std::max(foliage.reach_, foliage.tip(foliage.columns() - 1).norm());
    }
  }
  return foliage;
}

void Foliage::CutTranslated(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const Eigen::Vector3d& axis,
                            double radius) {
  const Eigen::Isometry3d T_centre_map = T_map_centre_.inverse();
  const Eigen::Vector3d a = T_centre_map * from, b = T_centre_map * to;
  const Eigen::Vector3d n = (T_centre_map.linear() * axis).normalized();
  const Eigen::Vector3d stem(0.0, 0.0, -target_.half.z());  // at the shape's bottom
  // Nothing to cut when the swept disc stays beyond every column's end.
  const Eigen::Vector3d ab = b - a;
  const double t = ab.squaredNorm() > 0.0 ? std::clamp(-a.dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  if ((a + t * ab).norm() > reach_ + radius) return;
  const long cut_before = cut_columns_;
  for (std::size_t i = 0; i < height_.size(); ++i) {
    // Along the column's line from its base, where the crossing is measured.
    const double depth = root_[i].dot(normal_[i]), length = depth + height_[i];
    const Eigen::Vector3d base = root_[i] - depth * normal_[i];
    const double s = FirstCrossing(normal_[i], length, a - base, b - base, n, radius, stem - base);
    if (s < length) {
      height_[i] = s - depth;
      ++cut_columns_;
    }
  }
  if (cut_columns_ == cut_before) return;  // every physics step while the cutter spins: mostly in the air
  reach_ = 0.0;
  for (int i = 0; i < columns(); ++i) reach_ = std::max(reach_, tip(i).norm());
}

int Foliage::CellOf(const Eigen::Vector3d& p) const {
  const double polar = std::acos(std::clamp(p.z() / p.norm(), -1.0, 1.0));
  double azimuth = std::atan2(p.y(), p.x());
  if (azimuth < 0.0) azimuth += 2.0 * M_PI;
  const int r = std::clamp(static_cast<int>(polar / M_PI * rings_), 0, rings_ - 1);
  const int s = static_cast<int>(azimuth / (2.0 * M_PI) * segments_) % segments_;
  return r * segments_ + s;
}

int Foliage::ColumnOf(const Eigen::Vector3d& p) const {
  // p's squared distance from column i's line.
  const auto off_line = [&](int i) {
    const auto k = static_cast<std::size_t>(i);
    const Eigen::Vector3d v = p - root_[k];
    const double along = v.dot(normal_[k]);
    return v.squaredNorm() - along * along;
  };
  // A first step to the cell under p's foot on the tangent plane of p's own cell: the lines fan
  // out from a curved target, so such steps overshoot (by 1 + height x curvature, near 2 at a
  // long ellipsoid's ends) and can swing to and fro; the rest downhill over neighbouring cells.
  int i = CellOf(p);
  const auto k = static_cast<std::size_t>(i);
  const Eigen::Vector3d foot = p - (p - root_[k]).dot(normal_[k]) * normal_[k];
  if (foot.squaredNorm() > 1e-18) {
    const int j = CellOf(foot);
    if (off_line(j) < off_line(i)) i = j;
  }
  constexpr int kMaxSteps = 32;  // cells; seen: 0-3
  for (int step = 0; step < kMaxSteps; ++step) {
    const int ring = i / segments_, segment = i % segments_;
    int best = i;
    double best_off = off_line(i);
    for (int dr = -1; dr <= 1; ++dr) {
      for (int ds = -1; ds <= 1; ++ds) {
        int r = ring + dr, s = segment + ds;
        if (r < 0 || r >= rings_) {  // over the pole: the ring itself, half round
          r = ring;
          s += segments_ / 2;
        }
        const int n = r * segments_ + (s + segments_) % segments_;
        const double off = off_line(n);
        if (off < best_off) {
          best = n;
          best_off = off;
        }
      }
    }
    if (best == i) break;
    i = best;
  }
  return i;
}

double Foliage::BeyondTip(const Eigen::Vector3d& p, int column) const {
  const auto i = static_cast<std::size_t>(column);
  return (p - root_[i]).dot(normal_[i]) - height_[i];
}

bool Foliage::InFoliage(const Eigen::Vector3d& p) const {
  const double distance = p.norm();
  if (distance < 1e-9) return true;
  if (distance > reach_) return false;
  return BeyondTip(p, ColumnOf(p)) <= 0.0;
}

bool Foliage::Reaches(const Eigen::Vector3d& point) const { return InFoliage(T_map_centre_.inverse() * point); }

Eigen::Vector3d Foliage::CutBack(const Eigen::Vector3d& p) const {
  if (p.squaredNorm() < 1e-18) return p;
  const int i = ColumnOf(p);
  const double excess = BeyondTip(p, i);
  return excess > 0.0 ? Eigen::Vector3d(p - excess * normal(i)) : p;
}

double Foliage::ExitRadius(const Eigen::Vector3d& d) const {
  // Bisection between the centre (in the foliage) and just past the farthest tip (outside it).
  double in = 0.0, out = reach_ + 0.01;
  for (int k = 0; k < 24; ++k) {  // 1 m / 2^24: well under a micrometre
    const double s = 0.5 * (in + out);
    (InFoliage(s * d) ? in : out) = s;
  }
  return in;
}

bool Foliage::ReachesCylinder(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const {
  constexpr double kStep = 0.01;  // m, about a leaf
  const Eigen::Vector3d axis = b - a;
  const double length = axis.norm();
  const Eigen::Vector3d z = length > 1e-9 ? Eigen::Vector3d(axis / length) : Eigen::Vector3d::UnitZ();
  // The samples' pattern is laid out in the map frame, then taken to the centre frame once.
  const Eigen::Isometry3d T_centre_map = T_map_centre_.inverse();
  const Eigen::Matrix3d& R = T_centre_map.linear();
  const Eigen::Vector3d across_map = z.unitOrthogonal();
  const Eigen::Vector3d x = R * across_map, y = R * z.cross(across_map);
  const Eigen::Vector3d start = T_centre_map * a, step = R * axis;
  const int along = std::max(1, static_cast<int>(std::ceil(length / kStep)));
  const int round = std::max(6, static_cast<int>(std::ceil(2.0 * M_PI * radius / kStep)));
  const int across = std::max(1, static_cast<int>(std::ceil(radius / kStep)));
  for (int i = 0; i <= along; ++i) {
    const Eigen::Vector3d c = start + step * (static_cast<double>(i) / along);
    if (InFoliage(c)) return true;
    // The mantle at every step; the caps' discs at the two ends.
    const int rings = i == 0 || i == along ? across : 1;
    for (int ring = 1; ring <= rings; ++ring) {
      const double r = radius * (rings == 1 ? 1.0 : static_cast<double>(ring) / rings);
      for (int k = 0; k < round; ++k) {
        const double angle = 2.0 * M_PI * k / round;
        if (InFoliage(c + r * (std::cos(angle) * x + std::sin(angle) * y))) return true;
      }
    }
  }
  return false;
}

void Foliage::Cut(const BladeDisc& from, const BladeDisc& to) {
  const Eigen::Vector3d a0 = from.axis.normalized(), a1 = to.axis.normalized();
  const double angle = std::acos(std::clamp(a0.dot(a1), -1.0, 1.0));
  const int steps = std::max(1, static_cast<int>(std::ceil(angle / (M_PI / 180.0))));
  const Eigen::Quaterniond turn = Eigen::Quaterniond::FromTwoVectors(a0, a1);
  for (int k = 0; k < steps; ++k) {
    const double f0 = static_cast<double>(k) / steps, f1 = static_cast<double>(k + 1) / steps;
    const Eigen::Vector3d axis = Eigen::Quaterniond::Identity().slerp(0.5 * (f0 + f1), turn) * a0;
    CutTranslated(from.centre + f0 * (to.centre - from.centre), from.centre + f1 * (to.centre - from.centre), axis,
                  from.radius + 0.5 * (f0 + f1) * (to.radius - from.radius));
  }
}

double Foliage::NormalCosine(std::size_t i) const { return std::max(0.1, std::abs(direction_[i].dot(normal_[i]))); }

CutQuality Foliage::Measure(double tolerance) const {
  CutQuality q;
  double area = 0.0, within = 0.0, upper_area = 0.0, upper_within = 0.0;
  for (std::size_t i = 0; i < height_.size(); ++i) {
    const int column = static_cast<int>(i);
    const double r = ExitRadius(direction_[i]), t = root_[i].norm(), w = solid_angle_[i];
    q.overgrowth_volume += w * (std::pow(std::max(r, t), 3) - std::pow(t, 3)) / 3.0;
    q.overcut_volume += w * (std::pow(t, 3) - std::pow(std::min(r, t), 3)) / 3.0;
    q.target_volume += w * std::pow(t, 3) / 3.0;
    q.max_overgrowth = std::max(q.max_overgrowth, height_[i]);
    if (OnTheGround(column, tolerance)) continue;
    // The surface element the column's cell spans at its tip's distance from the centre, tilted
    // by the normal's lean off the cell's direction (on a ball: the cell's area at the tip).
    const double element = w * tip(column).squaredNorm() / NormalCosine(i);
    const double near = std::abs(height_[i]) <= tolerance ? element : 0.0;
    area += element;
    within += near;
    if (direction_[i].z() >= 0.0) {
      upper_area += element;
      upper_within += near;
    }
  }
  q.surface_within_tolerance = area > 0.0 ? within / area : 0.0;
  q.upper_surface_within_tolerance = upper_area > 0.0 ? upper_within / upper_area : 0.0;
  return q;
}

std::vector<Eigen::Vector3d> Foliage::SurfacePoints() const {
  std::vector<Eigen::Vector3d> points;
  points.reserve(height_.size());
  for (int i = 0; i < columns(); ++i) points.push_back(T_map_centre_ * tip(i));
  return points;
}

void Foliage::WritePly(const std::string& path) const {
  std::ostringstream out;
  out << "ply\nformat binary_little_endian 1.0\ncomment trimbot foliage: leaf surface, map frame, m\n"
      << "element vertex " << height_.size() << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "property float distance\nend_header\n";
  const std::vector<Eigen::Vector3d> points = SurfacePoints();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const float values[4] = {static_cast<float>(points[i].x()), static_cast<float>(points[i].y()),
                             static_cast<float>(points[i].z()), static_cast<float>(height_[i])};
    char bytes[sizeof(values)];
    std::memcpy(bytes, values, sizeof(values));  // little-endian hosts only (x86-64, arm64)
    out.write(bytes, sizeof(bytes));
  }
  WriteFileAtomically(path, out.str());
}

}  // namespace trimbot::garden
