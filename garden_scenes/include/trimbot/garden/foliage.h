#pragma once
// A topiary's foliage as ground truth that can be cut. The target is the trimmed shape of the
// garden file (a superellipsoid: a ball or ellipsoid, a rounded cylinder, a rounded box); the
// leaves lie on a surface displaced from it by leaf clumps and by the season's outgrowth (the
// surface ObjectMesh renders). Foliage keeps that surface as a height field over the target: a
// column of foliage stands on the target at each of a grid of directions from the shape's centre
// and runs along the target's normal there, as shoots grow out of a clipped surface. (Columns
// running radially from the centre would lean 30-40 deg off a box's face near its corners: leaves
// rooted beside a blade's swath would hang over it, where nothing grows.) A blade disc sweeping
// through a column severs what lies beyond, so cutting shortens columns;
// what stays is measured against the target as van Marrewijk et al. (Biosystems Engineering 214,
// 2022) measured the robot's cuts: the share of the surface within 2 cm of the target.
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "trimbot/garden/garden.h"

namespace trimbot::garden {

// A superellipsoid |x/a|^n + |y/b|^n)^(m/n) + |z/c|^m = 1 about the shape's centre.
struct Superellipsoid {
  Eigen::Vector3d half = Eigen::Vector3d::Constant(0.5);  // m: semi-axes a, b, c
  double horizontal_exponent = 2.0;                       // n: 2 round, larger flatter sides
  double vertical_exponent = 2.0;                         // m

  // Distance from the centre to the surface along a unit direction.
  double Radius(const Eigen::Vector3d& direction) const;
  // Outward unit normal at a point on (or near) the surface.
  Eigen::Vector3d Normal(const Eigen::Vector3d& point) const;
  // Volume enclosed, m^3.
  double Volume() const;
};

// The trimmed shape of a garden object (ball, ellipsoid: exponents 2; cylinder: vertical 6; box: 6).
Superellipsoid TargetShape(const GardenObject& object);

// Where the leaves are along a direction from the shape's centre: the target's surface pushed out
// by leaf clumps (`clump_depth`) and by the season's outgrowth (`growth` in 0..1, conditions.h), in
// seeded noise of the garden's appearance; never below the shape's bottom. One formula for the
// rendered mesh and the foliage that is cut.
class FoliageGrowth {
 public:
  FoliageGrowth(const GardenObject& object, std::uint64_t appearance_seed, double growth);
  // How far the leaves stand out along the target's normal where a ray from the centre along the
  // unit `direction` meets the target (m; negative where a clump dips below it).
  double Outgrowth(const Eigen::Vector3d& direction) const;
  // That leaf surface point, in the shape's centre frame.
  Eigen::Vector3d SurfacePoint(const Eigen::Vector3d& direction) const;
  const Superellipsoid& target() const { return target_; }

 private:
  Superellipsoid target_;
  std::uint64_t seed_;
  double clump_depth_, clump_scale_, growth_;
};

// A blade's cutting disc: centre and axis (the disc's normal) in the map frame.
struct BladeDisc {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double radius = 0.1;  // m
};

struct CutQuality {
  // Share of the foliage surface within the tolerance of the target. Not counted: where the target
  // lies within the tolerance of the ground plane the bush stands on (a box's or cylinder's flat
  // underside): no leaf grows out there, so it would count as within however the bush was cut.
  double surface_within_tolerance = 0.0;
  // The same over the surface above the target's centre: the half the arm reaches from a standoff
  // (docs/design.md, Trimming: no blade pose below a bush's equator has a solution).
  double upper_surface_within_tolerance = 0.0;
  double overgrowth_volume = 0.0;  // m^3 of foliage outside the target
  double overcut_volume = 0.0;     // m^3 of the target without foliage (cut into)
  double target_volume = 0.0;      // m^3
  double max_overgrowth = 0.0;     // m: the highest column over the target
};

class Foliage {
 public:
  // The object's foliage grown for `growth`, on rings x segments directions (polar x azimuth).
  static Foliage Grown(const GardenObject& object, std::uint64_t appearance_seed, double growth, int rings = 90,
                       int segments = 180);

  // Removes what the disc severs moving from `from` to `to`: translated linearly, its axis turned
  // in steps of at most 1 deg (each step swept with its mean axis). A column the swept disc
  // crosses ends where the blade first met it.
  void Cut(const BladeDisc& from, const BladeDisc& to);

  // Against the target: each column's height is the surface's distance along the target's normal;
  // the volumes integrate where the foliage ends along rays from the centre.
  CutQuality Measure(double tolerance = 0.02) const;
  // The leaf surface's points in the map frame (one per column).
  std::vector<Eigen::Vector3d> SurfacePoints() const;
  // Binary little-endian PLY of the surface points with their signed distance to the target (m,
  // property `distance`), written atomically.
  void WritePly(const std::string& path) const;

  // Whether a map point lies inside the foliage: at most its column's height above the target,
  // its column being the one whose line passes through it (nearest the target's point under it).
  bool Reaches(const Eigen::Vector3d& point) const;
  // A point of the foliage as grown (centre frame) moved in along its column to where cuts have
  // left the column's leaves; unchanged where it lies below them (the drawn mesh follows the cuts).
  Eigen::Vector3d CutBack(const Eigen::Vector3d& point) const;
  // Whether a solid cylinder (axis end points `a`, `b` in the map frame, `radius`) reaches into the
  // foliage: its axis, its mantle and its end caps sampled every centimetre. A point test with the
  // radius as a margin along the ray from the bush's centre would not do: it counts an end cap just
  // behind a blade that has cut the leaves in front of it as in them.
  bool ReachesCylinder(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const;
  // Columns shortened by cuts so far (a drawing of the foliage is stale when it grew).
  long cut_columns() const { return cut_columns_; }

  // Whether the ground plane the shape stands on lies within `tolerance` of column i's root, along
  // the column (no leaf grows out there: Measure leaves it out).
  bool OnTheGround(int i, double tolerance) const { return floor_height_[static_cast<std::size_t>(i)] < tolerance; }

  // Column i (all in the centre frame): it stands on the target at `root`, where a ray from the
  // centre along `direction` meets it, and runs along the target's outward unit `normal` there,
  // from its `base` (the line's point nearest the centre) to its `tip`, `height` m beyond the
  // target (negative: cut into it).
  int columns() const { return static_cast<int>(height_.size()); }
  int rings() const { return rings_; }  // columns are ring-major: i = ring * segments + segment
  int segments() const { return segments_; }
  const Eigen::Vector3d& direction(int i) const { return direction_[static_cast<std::size_t>(i)]; }
  const Eigen::Vector3d& root(int i) const { return root_[static_cast<std::size_t>(i)]; }
  const Eigen::Vector3d& normal(int i) const { return normal_[static_cast<std::size_t>(i)]; }
  double height(int i) const { return height_[static_cast<std::size_t>(i)]; }
  Eigen::Vector3d base(int i) const { return root(i) - root(i).dot(normal(i)) * normal(i); }
  Eigen::Vector3d tip(int i) const { return root(i) + height(i) * normal(i); }
  const Superellipsoid& target() const { return target_; }
  // Pose of the shape's centre frame in the map frame.
  const Eigen::Isometry3d& pose() const { return T_map_centre_; }

 private:
  void CutTranslated(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const Eigen::Vector3d& axis,
                     double radius);
  // The column of the cell a ray from the centre through p (centre frame) crosses.
  int CellOf(const Eigen::Vector3d& p) const;
  // The column whose line passes nearest p (centre frame; through it but for the grid).
  int ColumnOf(const Eigen::Vector3d& p) const;
  // How far p (centre frame) lies beyond the tip along `column`'s normal (<= 0: in its leaves).
  double BeyondTip(const Eigen::Vector3d& p, int column) const;
  // Reaches, for a point in the centre frame.
  bool InFoliage(const Eigen::Vector3d& p) const;
  // Where the foliage ends along a ray from the centre (unit `direction`, centre frame).
  double ExitRadius(const Eigen::Vector3d& direction) const;
  // |cos| of the angle between column i's direction from the centre and its normal (at least 0.1).
  double NormalCosine(std::size_t i) const;

  Superellipsoid target_;
  int rings_ = 0, segments_ = 0;
  long cut_columns_ = 0;
  double reach_ = 0.0;  // m: the farthest tip from the centre (nothing beyond is foliage)
  Eigen::Isometry3d T_map_centre_ = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3d> direction_;  // unit, in the centre frame
  std::vector<double> solid_angle_;         // sr per column
  std::vector<Eigen::Vector3d> root_;       // where the column meets the target
  std::vector<Eigen::Vector3d> normal_;     // the target's outward unit normal there
  std::vector<double> height_;              // m along the normal: where the foliage ends
  std::vector<double> floor_height_;        // m along the normal: the bottom plane (foliage never below)
};

}  // namespace trimbot::garden
