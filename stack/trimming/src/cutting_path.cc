#include "trimbot/trimming/cutting_path.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <set>
#include <utility>

namespace trimbot::trimming {

Eigen::Vector3d SurfaceNormal(const perception::TopiaryShape& target, const Eigen::Vector3d& p) {
  constexpr double h = 1e-5;
  Eigen::Vector3d g;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(k);
    g(k) = (target.RadialDistance(p + e) - target.RadialDistance(p - e)) / (2.0 * h);
  }
  return g.normalized();
}

namespace {

// A rotation whose z axis is `z` (unit) and whose x axis is `x_hint` made perpendicular to it.
Eigen::Matrix3d FrameWithZ(const Eigen::Vector3d& z, const Eigen::Vector3d& x_hint) {
  Eigen::Vector3d x = x_hint - x_hint.dot(z) * z;
  if (x.norm() < 1e-6) {
    const Eigen::Vector3d helper = std::abs(z.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    x = helper.cross(z);
  }
  x.normalize();
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = z.cross(x);
  R.col(2) = z;
  return R;
}

// A sphere the cutter cannot leave: about the first link's origin (on the first joint's axis, so
// fixed in base_link), of the sum of the distances between consecutive link origins (rigid links,
// the triangle inequality). Poses outside it are refused without inverse kinematics, which takes
// its full budget of starts to give up.
std::pair<Eigen::Vector3d, double> ReachSphere(const arm::ArmKinematics& kinematics, const Eigen::VectorXd& q) {
  const std::vector<Eigen::Isometry3d> links = kinematics.LinkPoses(q);
  double reach = 0.0;
  for (std::size_t i = 1; i < links.size(); ++i) reach += (links[i].translation() - links[i - 1].translation()).norm();
  return {links.front().translation(), reach};
}

}  // namespace

Eigen::Isometry3d BladePoseAt(const perception::TopiaryShape& target, const Eigen::Vector3d& direction,
                              const Eigen::Vector3d& x_hint) {
  Eigen::Isometry3d blade = Eigen::Isometry3d::Identity();
  blade.translation() = target.centre + target.Radius(direction) * direction;
  blade.linear() = FrameWithZ(-SurfaceNormal(target, blade.translation()), x_hint);
  return blade;
}

Eigen::Isometry3d BladeSurface::PoseAt(const Eigen::Vector3d& direction, const Eigen::Vector3d& x_hint) const {
  if (depth == 0.0 || (seen && !seen(direction))) return BladePoseAt(fit, direction, x_hint);
  return BladePoseAt(aimed(), direction, x_hint);
}

std::vector<Eigen::Isometry3d> CuttingPoses(const BladeSurface& surface, const CuttingPoseOptions& options) {
  const perception::TopiaryShape target = surface.aimed();
  // Directions from the centre on a Fibonacci sphere, as many as the surface holds blade spacings
  // (the surface of the ellipsoid through the semi-axes, Knud Thomsen's approximation).
  const Eigen::Vector3d& s = target.half;
  constexpr double p = 1.6075;
  const double area =
      4.0 * M_PI *
      std::pow((std::pow(s.x() * s.y(), p) + std::pow(s.x() * s.z(), p) + std::pow(s.y() * s.z(), p)) / 3.0, 1.0 / p);
  const int count = std::max(8, static_cast<int>(std::ceil(area / (options.spacing * options.spacing))));
  const Eigen::Matrix3d R_yaw = Eigen::AngleAxisd(target.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k < count; ++k) {
    const double z = 1.0 - 2.0 * (k + 0.5) / count, r = std::sqrt(1.0 - z * z);
    const Eigen::Vector3d d =
        R_yaw * Eigen::Vector3d(r * std::cos(golden_angle * k), r * std::sin(golden_angle * k), z);
    const Eigen::Isometry3d blade = surface.PoseAt(d);
    const Eigen::Vector3d point = blade.translation();
    if (point.z() < options.min_height) continue;
    const Eigen::Vector3d to_base = (Eigen::Vector3d(0.0, 0.0, point.z()) - point).normalized();
    const Eigen::Vector3d normal = -blade.linear().col(2);
    const bool faces_base = normal.dot(to_base) >= std::cos(options.max_facing_angle);
    // The crown (surface turned up more than sideways: the top of a ball, the flat top of a
    // cylinder or box) faces no standoff; the arm reaches over it from the side it lies on. Each
    // standoff takes the sector within 45 deg of its bearing from the centre, so four standoffs at
    // right angles (a box's faces or corners) share the crown without cutting any of it twice.
    const Eigen::Vector3d from_centre(point.x() - target.centre.x(), point.y() - target.centre.y(), 0.0);
    const bool crown_on_this_side =
        normal.z() >= normal.head<2>().norm() && from_centre.dot(to_base) >= std::cos(M_PI / 4) * from_centre.norm();
    if (!faces_base && !crown_on_this_side) continue;
    poses.push_back(blade);
  }
  return poses;
}

perception::TopiaryShape Offset(const perception::TopiaryShape& target, double offset) {
  perception::TopiaryShape moved = target;
  moved.half = (target.half.array() + offset).max(1e-3).matrix();
  return moved;
}

void SetTargetEnvironment(robot::CollisionModel* collision, const perception::TopiaryShape& target, double offset) {
  // The offset target on a polar grid (rings x segments plus the two poles), as a convex
  // polyhedron (a superellipsoid of exponents >= 2 is convex).
  constexpr int kRings = 16, kSegments = 32;
  const perception::TopiaryShape moved = Offset(target, offset);
  std::vector<Eigen::Vector3d> vertices;
  const auto surface = [&](const Eigen::Vector3d& d) { return Eigen::Vector3d(target.centre + moved.Radius(d) * d); };
  vertices.push_back(surface(Eigen::Vector3d::UnitZ()));
  for (int r = 1; r < kRings; ++r) {
    const double polar = M_PI * r / kRings;
    for (int s = 0; s < kSegments; ++s) {
      const double azimuth = 2.0 * M_PI * s / kSegments;
      vertices.push_back(surface(
          Eigen::Vector3d(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth), std::cos(polar))));
    }
  }
  vertices.push_back(surface(-Eigen::Vector3d::UnitZ()));
  const int bottom = static_cast<int>(vertices.size()) - 1;
  const auto at = [](int ring, int segment) { return 1 + (ring - 1) * kSegments + (segment % kSegments); };
  std::vector<std::array<int, 3>> triangles;
  for (int s = 0; s < kSegments; ++s) {
    triangles.push_back({0, at(1, s), at(1, s + 1)});
    for (int r = 1; r + 1 < kRings; ++r) {
      triangles.push_back({at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      triangles.push_back({at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
    triangles.push_back({at(kRings - 1, s), bottom, at(kRings - 1, s + 1)});
  }
  collision->environment().Clear();
  collision->environment().AddGround("ground", 0.0);
  collision->environment().AddConvex("target", vertices, triangles);
}

double CheckDepth(const perception::TopiaryShape& target, double aimed_depth, double spacing, double blade_thickness) {
  const double radius = std::max(1e-3, target.half.minCoeff() - aimed_depth);
  const double neighbours = spacing * std::sqrt(2.0 / std::sqrt(3.0));
  return aimed_depth + 0.5 * blade_thickness + neighbours * neighbours / (8.0 * radius);
}

std::vector<Eigen::VectorXd> BladeLine(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade,
                                       const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                       const arm::ArmPlannerParameters& arm_parameters,
                                       const std::function<bool(const Eigen::VectorXd&)>& valid) {
  const Eigen::Isometry3d T_blade_cutter = T_cutter_blade.inverse();
  const std::vector<Eigen::Isometry3d> line =
      arm::PosesAlongLine(kinematics.EndEffectorPose(a) * T_cutter_blade,
                          kinematics.EndEffectorPose(b) * T_cutter_blade, arm_parameters.cartesian_step);
  // No joint turns more than cartesian_max_joint_step a step: b on another branch is out of reach.
  const double most = arm_parameters.cartesian_max_joint_step * static_cast<double>(line.size());
  if (kinematics.JointDifference(a, b).cwiseAbs().maxCoeff() > most) return {};
  // A step may turn a joint up to cartesian_max_joint_step: checked in between as any motion is.
  const auto checked = [&](const Eigen::VectorXd& from, const Eigen::VectorXd& to) {
    if (!valid) return true;
    const std::vector<Eigen::VectorXd> states = arm::JointSteps(from, to, arm_parameters.collision_step);
    return std::all_of(states.begin(), states.end(), valid);
  };
  std::vector<Eigen::VectorXd> configurations;
  Eigen::VectorXd previous = a;
  for (std::size_t k = 0; k + 1 < line.size(); ++k) {
    const std::optional<Eigen::VectorXd> q =
        kinematics.InverseKinematicsNear(line[k] * T_blade_cutter, previous, arm_parameters.ik);
    if (!q || (*q - previous).cwiseAbs().maxCoeff() > arm_parameters.cartesian_max_joint_step) return {};
    if (!checked(previous, *q)) return {};
    configurations.push_back(*q);
    previous = *q;
  }
  const Eigen::VectorXd end = previous + kinematics.JointDifference(previous, b);  // b, on the way's unwrapping
  if ((end - previous).cwiseAbs().maxCoeff() > arm_parameters.cartesian_max_joint_step) return {};  // another branch
  if (!checked(previous, end)) return {};
  configurations.push_back(end);
  return configurations;
}

CuttingChecks MakeCuttingChecks(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade,
                                robot::CollisionModel* collision, const perception::TopiaryShape& target, double depth,
                                const arm::ArmPlannerParameters& arm_parameters,
                                const std::function<bool(const Eigen::VectorXd&)>& also_valid) {
  SetTargetEnvironment(collision, target, -depth);
  CuttingChecks checks;
  checks.valid = [collision, also_valid](const Eigen::VectorXd& q) {
    return !collision->Check(q).collision && (!also_valid || also_valid(q));
  };
  checks.way = [&kinematics, T_cutter_blade, arm_parameters, valid = checks.valid](const Eigen::VectorXd& a,
                                                                                   const Eigen::VectorXd& b) {
    const std::vector<Eigen::VectorXd> way =
        arm::JointSteps(a, a + kinematics.JointDifference(a, b), arm_parameters.collision_step);
    if (std::all_of(way.begin(), way.end(), valid)) return way;
    return BladeLine(kinematics, T_cutter_blade, a, b, arm_parameters, valid);
  };
  checks.free_move = [way = checks.way](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return !way(a, b).empty();
  };
  return checks;
}

double JointMoveTime(const arm::ArmKinematics& kinematics, const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                     double velocity_scale, double acceleration) {
  const Eigen::VectorXd difference = kinematics.JointDifference(from, to);
  double time = 0.0;
  for (int j = 0; j < kinematics.joints(); ++j) {
    const double d = std::abs(difference(j));
    const double v = velocity_scale * kinematics.limits()[static_cast<std::size_t>(j)].velocity;
    time = std::max(time, d < v * v / acceleration ? 2.0 * std::sqrt(d / acceleration) : d / v + v / acceleration);
  }
  return time;
}

namespace {

// The GTSP of a cutting path: node 0 the start (its own cluster), then each reachable pose's free
// solutions over its rolls. Fills `path`'s counts and unreachable poses.
struct CuttingInstance {
  GtspInstance gtsp;
  std::vector<Eigen::VectorXd> nodes;
  std::vector<int> pose_of_node;
  std::vector<int> cluster_of_node;
  std::vector<Eigen::Isometry3d> blade_of_node;
};

CuttingInstance BuildInstance(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade,
                              const Eigen::VectorXd& start, const std::vector<Eigen::Isometry3d>& blade_poses,
                              const std::function<bool(const Eigen::VectorXd&)>& valid,
                              const CuttingPathOptions& options, CuttingPath* path, double* reach_out) {
  CuttingInstance c;
  c.nodes = {start};
  c.pose_of_node = {-1};
  c.blade_of_node = {Eigen::Isometry3d::Identity()};
  c.cluster_of_node = {0};
  c.gtsp.clusters.push_back({0});
  const Eigen::Isometry3d T_blade_cutter = T_cutter_blade.inverse();
  const auto [shoulder, reach] = ReachSphere(kinematics, start);
  *reach_out = reach;
  for (std::size_t k = 0; k < blade_poses.size(); ++k) {
    std::vector<int> cluster;
    const bool within_reach = ((blade_poses[k] * T_blade_cutter).translation() - shoulder).norm() <= reach;
    for (int r = 0; within_reach && r < options.rolls; ++r) {
      const Eigen::Isometry3d blade =
          blade_poses[k] * Eigen::AngleAxisd(2.0 * M_PI * r / options.rolls, Eigen::Vector3d::UnitZ());
      for (const Eigen::VectorXd& q : kinematics.InverseKinematics(blade * T_blade_cutter, options.ik).solutions) {
        if (!valid(q)) continue;
        cluster.push_back(static_cast<int>(c.nodes.size()));
        c.nodes.push_back(q);
        c.pose_of_node.push_back(static_cast<int>(k));
        c.blade_of_node.push_back(blade);
        c.cluster_of_node.push_back(static_cast<int>(c.gtsp.clusters.size()));
      }
    }
    if (cluster.empty()) {
      path->unreachable.push_back(static_cast<int>(k));
    } else {
      c.gtsp.clusters.push_back(cluster);
    }
  }
  path->clusters = static_cast<int>(c.gtsp.clusters.size()) - 1;
  path->nodes = static_cast<int>(c.nodes.size()) - 1;
  const auto n = static_cast<Eigen::Index>(c.nodes.size());
  c.gtsp.cost.resize(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j)
      c.gtsp.cost(i, j) =
          i == j ? 0.0
                 : JointMoveTime(kinematics, c.nodes[static_cast<std::size_t>(i)], c.nodes[static_cast<std::size_t>(j)],
                                 options.velocity_scale, options.acceleration);
  }
  return c;
}

// Lazy edge checking: solve, check the tour's moves; where one is refused, check every move
// between the two poses' solutions (their neighbours collide alike). A refused move becomes one
// the arm planner plans round obstacles, costed as the way through the start (always open to the
// planner: it plans the moves from and back to the start too), and the tour is solved again until
// every move it makes has been checked. Returns the moves to plan.
GtspTour SolveWithCheckedMoves(CuttingInstance* c,
                               const std::function<bool(const Eigen::VectorXd&, const Eigen::VectorXd&)>& free_move,
                               const CuttingPathOptions& options, CuttingPath* path,
                               std::set<std::pair<int, int>>* planned) {
  const Eigen::MatrixXd direct = c->gtsp.cost;
  std::set<std::pair<int, int>> checked_clusters;
  const auto check_clusters = [&](int a, int b) {
    const auto key =
        std::minmax(c->cluster_of_node[static_cast<std::size_t>(a)], c->cluster_of_node[static_cast<std::size_t>(b)]);
    if (!checked_clusters.insert(key).second) return false;
    for (int u : c->gtsp.clusters[static_cast<std::size_t>(key.first)]) {
      for (int v : c->gtsp.clusters[static_cast<std::size_t>(key.second)]) {
        if (free_move(c->nodes[static_cast<std::size_t>(u)], c->nodes[static_cast<std::size_t>(v)])) continue;
        c->gtsp.cost(u, v) = direct(u, 0) + direct(0, v);
        c->gtsp.cost(v, u) = direct(v, 0) + direct(0, u);
        planned->insert(std::minmax(u, v));
        ++path->refused_moves;
      }
    }
    return true;
  };
  GtspTour tour;
  for (int round = 0; round < options.max_lazy_rounds; ++round) {
    tour = SolveGtspLargeNeighbourhood(c->gtsp, options.search);
    bool newly_checked = false;
    for (std::size_t i = 0; i < tour.nodes.size(); ++i) {
      const int a = tour.nodes[i], b = tour.nodes[(i + 1) % tour.nodes.size()];
      if (a != 0 && b != 0 && check_clusters(a, b) && planned->count(std::minmax(a, b))) newly_checked = true;
    }
    if (!newly_checked) break;
  }
  return tour;
}

}  // namespace

CuttingPath PlanCuttingPath(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade,
                            const Eigen::VectorXd& start, const std::vector<Eigen::Isometry3d>& blade_poses,
                            const std::function<bool(const Eigen::VectorXd&)>& valid,
                            const std::function<bool(const Eigen::VectorXd&, const Eigen::VectorXd&)>& free_move,
                            const CuttingPathOptions& options) {
  CuttingPath path;
  double reach = 0.0;
  CuttingInstance c = BuildInstance(kinematics, T_cutter_blade, start, blade_poses, valid, options, &path, &reach);
  if (path.clusters == 0) {
    path.failure = "no blade pose of " + std::to_string(blade_poses.size()) +
                   " has a collision-free arm solution (the arm reaches " + std::to_string(reach) +
                   " m from its shoulder)";
    return path;
  }
  std::set<std::pair<int, int>> planned;
  GtspTour tour = SolveWithCheckedMoves(&c, free_move, options, &path, &planned);
  // The tour from the start round and back to it.
  std::rotate(tour.nodes.begin(), std::find(tour.nodes.begin(), tour.nodes.end(), 0), tour.nodes.end());
  tour.nodes.push_back(0);
  for (std::size_t i = 0; i < tour.nodes.size(); ++i) {
    const int node = tour.nodes[i];
    path.configurations.push_back(c.nodes[static_cast<std::size_t>(node)]);
    if (i > 0)
      path.planned.push_back(node == 0 || tour.nodes[i - 1] == 0 ||
                             planned.count(std::minmax(tour.nodes[i - 1], node)) > 0);
    if (node == 0) continue;
    path.poses.push_back(c.pose_of_node[static_cast<std::size_t>(node)]);
    path.blades.push_back(c.blade_of_node[static_cast<std::size_t>(node)]);
  }
  path.motion_time = tour.cost;
  path.nearest_neighbour_time = SolveGtspNearestNeighbour(c.gtsp).cost;
  path.ok = true;
  return path;
}

}  // namespace trimbot::trimming
