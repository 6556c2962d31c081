#include "trimbot/trimming/plan_database.h"

#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "trimbot/common/input_error.h"
#include "trimbot/common/sqlite_file.h"

namespace trimbot::trimming {
namespace {

constexpr const char* kFormat = "trimbot cutting paths";
constexpr int kJoints = 6;

void WritePaths(sqlite3* db, const std::vector<StoredCuttingPath>& paths) {
  sqlite::Exec(db,
               "CREATE TABLE paths(id INTEGER PRIMARY KEY, n REAL, m REAL, cx REAL, cy REAL, cz REAL, yaw REAL,"
               " a REAL, b REAL, c REAL, motion_time REAL, steps INTEGER);"
               "CREATE TABLE steps(path INTEGER, step INTEGER, x REAL, y REAL, z REAL, qw REAL, qx REAL, qy REAL,"
               " qz REAL, j1 REAL, j2 REAL, j3 REAL, j4 REAL, j5 REAL, j6 REAL, PRIMARY KEY(path, step));");
  sqlite::Statement path_row = sqlite::Prepare(db, "INSERT INTO paths VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  sqlite::Statement step_row =
      sqlite::Prepare(db, "INSERT INTO steps VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const StoredCuttingPath& p = paths[i];
    const perception::TopiaryShape& t = p.target;
    const double values[] = {t.horizontal_exponent,
                             t.vertical_exponent,
                             t.centre.x(),
                             t.centre.y(),
                             t.centre.z(),
                             t.yaw,
                             t.half.x(),
                             t.half.y(),
                             t.half.z(),
                             p.motion_time};
    sqlite3_bind_int(path_row.get(), 1, static_cast<int>(i));
    for (int k = 0; k < 10; ++k) sqlite3_bind_double(path_row.get(), k + 2, values[k]);
    sqlite3_bind_int(path_row.get(), 12, static_cast<int>(p.blades.size()));
    sqlite::Step(db, path_row.get());
    for (std::size_t s = 0; s < p.blades.size(); ++s) {
      const Eigen::Quaterniond q(p.blades[s].linear());
      const Eigen::Vector3d x = p.blades[s].translation();
      sqlite3_bind_int(step_row.get(), 1, static_cast<int>(i));
      sqlite3_bind_int(step_row.get(), 2, static_cast<int>(s));
      const double pose[] = {x.x(), x.y(), x.z(), q.w(), q.x(), q.y(), q.z()};
      for (int k = 0; k < 7; ++k) sqlite3_bind_double(step_row.get(), k + 3, pose[k]);
      for (int j = 0; j < kJoints; ++j) sqlite3_bind_double(step_row.get(), 10 + j, p.configurations[s](j));
      sqlite::Step(db, step_row.get());
    }
  }
}

std::vector<StoredCuttingPath> ReadPaths(sqlite3* db) {
  std::vector<StoredCuttingPath> paths;
  std::vector<int> steps;
  sqlite::Statement rows = sqlite::Prepare(db, "SELECT * FROM paths ORDER BY id");
  while (sqlite3_step(rows.get()) == SQLITE_ROW) {
    if (sqlite3_column_int(rows.get(), 0) != static_cast<int>(paths.size()))
      throw sqlite::SqlError("path ids are not 0, 1, 2, ...");
    StoredCuttingPath p;
    const auto v = [&](int k) { return sqlite3_column_double(rows.get(), k); };
    p.target.horizontal_exponent = v(1);
    p.target.vertical_exponent = v(2);
    p.target.centre = {v(3), v(4), v(5)};
    p.target.yaw = v(6);
    p.target.half = {v(7), v(8), v(9)};
    p.motion_time = v(10);
    if (!p.target.half.allFinite() || p.target.half.minCoeff() <= 0.0 || !p.target.centre.allFinite())
      throw sqlite::SqlError("path " + std::to_string(paths.size()) + " has no valid target");
    steps.push_back(sqlite3_column_int(rows.get(), 11));
    paths.push_back(p);
  }
  sqlite::Statement step_rows = sqlite::Prepare(db, "SELECT * FROM steps ORDER BY path, step");
  while (sqlite3_step(step_rows.get()) == SQLITE_ROW) {
    const int path = sqlite3_column_int(step_rows.get(), 0), step = sqlite3_column_int(step_rows.get(), 1);
    if (path < 0 || path >= static_cast<int>(paths.size()) ||
        step != static_cast<int>(paths[static_cast<std::size_t>(path)].blades.size()))
      throw sqlite::SqlError("step " + std::to_string(step) + " of path " + std::to_string(path) + " out of order");
    const auto v = [&](int k) { return sqlite3_column_double(step_rows.get(), k); };
    Eigen::Isometry3d blade = Eigen::Isometry3d::Identity();
    blade.translation() = Eigen::Vector3d(v(2), v(3), v(4));
    blade.linear() = Eigen::Quaterniond(v(5), v(6), v(7), v(8)).normalized().toRotationMatrix();
    Eigen::VectorXd q(kJoints);
    for (int j = 0; j < kJoints; ++j) q(j) = v(9 + j);
    paths[static_cast<std::size_t>(path)].blades.push_back(blade);
    paths[static_cast<std::size_t>(path)].configurations.push_back(q);
  }
  for (std::size_t i = 0; i < paths.size(); ++i) {
    if (static_cast<int>(paths[i].blades.size()) != steps[i])
      throw sqlite::SqlError("path " + std::to_string(i) + " has " + std::to_string(paths[i].blades.size()) +
                             " steps, its row says " + std::to_string(steps[i]));
  }
  return paths;
}

// The turn about z from the `stored` target to `target` as far as their shapes can tell: turns that
// map a shape onto itself are taken off - any turn where either has a round plan, quarter turns
// where both are square, half turns otherwise. A plan is round or square when its horizontal
// semi-axes differ by less than the cut's 2 cm (turning it moves its surface less than that): a
// fitted round bush's are apart by millimetres, and its yaw is what the base's heading made it.
double ShapeTurn(const perception::TopiaryShape& target, const perception::TopiaryShape& stored) {
  constexpr double kCutTolerance = 0.02;  // m
  const auto square = [](const perception::TopiaryShape& s) {
    return std::abs(s.half.x() - s.half.y()) < kCutTolerance;
  };
  const auto round = [&](const perception::TopiaryShape& s) {
    return square(s) && std::abs(s.horizontal_exponent - 2.0) < 1e-9;
  };
  if (round(target) || round(stored)) return 0.0;
  return std::remainder(target.yaw - stored.yaw, square(target) && square(stored) ? M_PI / 2.0 : M_PI);
}

}  // namespace

std::string ArmSignature(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(4);
  for (const arm::JointLimit& limit : kinematics.limits())
    text << limit.name << (limit.continuous ? " continuous " : " ") << limit.lower << ' ' << limit.upper << ' '
         << limit.velocity << ';';
  const Eigen::Isometry3d zero = kinematics.EndEffectorPose(Eigen::VectorXd::Zero(kinematics.joints()));
  const Eigen::Quaterniond q(zero.linear());
  text << " cutter at zero " << zero.translation().transpose() << ' ' << q.coeffs().transpose() << "; blade "
       << T_cutter_blade.translation().transpose();
  return text.str();
}

void CuttingPathDatabase::Save(const std::string& path, const std::string& arm_signature) const {
  sqlite::WriteAtomically(path, [&](sqlite3* db) {
    sqlite::WriteMeta(
        db, {{"format", kFormat}, {"version", std::to_string(kFormatVersion)}, {"arm_signature", arm_signature}});
    WritePaths(db, paths_);
  });
}

CuttingPathDatabase CuttingPathDatabase::Load(const std::string& path, const std::string& expected_arm_signature) {
  const sqlite::Database db = sqlite::OpenReadOnly(path, "cutting path database");
  CuttingPathDatabase database;
  std::string signature;
  try {
    if (sqlite::Meta(db.get(), "format") != kFormat) throw sqlite::SqlError("not a trimbot cutting path database");
    const std::string version = sqlite::Meta(db.get(), "version");
    if (version != std::to_string(kFormatVersion))
      throw InputError(path, "cutting path database version " + version + ", this build reads version " +
                                 std::to_string(kFormatVersion) + " (precompute it again)");
    signature = sqlite::Meta(db.get(), "arm_signature");
    database.paths_ = ReadPaths(db.get());
  } catch (const sqlite::SqlError& e) {
    throw InputError(path, std::string("not a valid cutting path database (") + e.what() + ")");
  }
  if (signature != expected_arm_signature)
    throw InputError(path, "the paths were planned for another arm or blade (" + signature +
                               "; this one: " + expected_arm_signature + ")");
  return database;
}

const StoredCuttingPath* CuttingPathDatabase::Nearest(const perception::TopiaryShape& target, double* distance) const {
  const StoredCuttingPath* nearest = nullptr;
  double best = std::numeric_limits<double>::infinity();
  for (const StoredCuttingPath& p : paths_) {
    if (std::abs(p.target.horizontal_exponent - target.horizontal_exponent) > 1e-9 ||
        std::abs(p.target.vertical_exponent - target.vertical_exponent) > 1e-9)
      continue;
    const double d = (p.target.centre - target.centre).norm() + (p.target.half - target.half).norm() +
                     target.half.mean() * std::abs(ShapeTurn(target, p.target));
    if (d < best) {
      best = d;
      nearest = &p;
    }
  }
  if (distance) *distance = best;
  return nearest;
}

StoredCuttingPath ToStored(const CuttingPath& path, const perception::TopiaryShape& target) {
  StoredCuttingPath stored;
  stored.target = target;
  stored.blades = path.blades;
  // The configurations between the start and the return to it.
  stored.configurations.assign(path.configurations.begin() + 1, path.configurations.end() - 1);
  stored.motion_time = path.motion_time;
  return stored;
}

CuttingPath AdaptCuttingPath(const arm::ArmKinematics& kinematics, const Eigen::Isometry3d& T_cutter_blade,
                             const Eigen::VectorXd& start, const StoredCuttingPath& stored, const BladeSurface& surface,
                             const std::function<bool(const Eigen::VectorXd&)>& valid,
                             const std::function<bool(const Eigen::VectorXd&, const Eigen::VectorXd&)>& free_move,
                             const CuttingPathOptions& options) {
  CuttingPath path;
  path.configurations.push_back(start);
  const perception::TopiaryShape target = surface.aimed();
  // From the stored target's frame to the new one's: its centre and yaw (the least turn that
  // gives the same shape: a round bush's poses stay on the side the base faces).
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(ShapeTurn(target, stored.target), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Isometry3d T_blade_cutter = T_cutter_blade.inverse();
  for (std::size_t k = 0; k < stored.blades.size(); ++k) {
    const Eigen::Vector3d direction = turn * (stored.blades[k].translation() - stored.target.centre).normalized();
    const Eigen::Isometry3d blade = surface.PoseAt(direction, turn * stored.blades[k].linear().col(0));
    const Eigen::VectorXd& previous = path.configurations.back();
    const bool first = path.configurations.size() == 1;  // the move from the start is the arm planner's
    std::optional<Eigen::VectorXd> q =
        kinematics.InverseKinematicsNear(blade * T_blade_cutter, stored.configurations[k], options.ik);
    if (q && !valid(*q)) q.reset();
    bool free = q && (first || free_move(previous, *q));
    if (!free) {
      // Repair locally: the quickest free move to any of the pose's solutions, else the valid one
      // nearest in time (a planned move), else leave the pose.
      double best_free = std::numeric_limits<double>::infinity(), best = best_free;
      std::optional<Eigen::VectorXd> nearest;
      for (const Eigen::VectorXd& other : kinematics.InverseKinematics(blade * T_blade_cutter, options.ik).solutions) {
        const double time = JointMoveTime(kinematics, previous, other, options.velocity_scale, options.acceleration);
        if (!valid(other)) continue;
        if (time < best) {
          best = time;
          nearest = other;
        }
        if (time < best_free && (first || free_move(previous, other))) {
          best_free = time;
          q = other;
          free = true;
        }
      }
      if (!free) q = nearest;
      ++path.refused_moves;
    }
    if (!q) {
      path.unreachable.push_back(static_cast<int>(k));
      continue;
    }
    path.planned.push_back(first || !free);
    path.configurations.push_back(*q);
    path.poses.push_back(static_cast<int>(k));
    path.blades.push_back(blade);
  }
  path.configurations.push_back(start);
  path.planned.push_back(true);
  path.clusters = static_cast<int>(path.poses.size());
  if (path.poses.empty()) {
    path.failure = "none of the stored path's " + std::to_string(stored.blades.size()) + " poses fits this target";
    return path;
  }
  for (std::size_t i = 0; i + 1 < path.configurations.size(); ++i)
    path.motion_time += JointMoveTime(kinematics, path.configurations[i], path.configurations[i + 1],
                                      options.velocity_scale, options.acceleration);
  path.ok = true;
  return path;
}

}  // namespace trimbot::trimming
