#include "trimbot/visual_localization/visual_map.h"

#include <sqlite3.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "trimbot/common/input_error.h"
#include "trimbot/common/random.h"
#include "trimbot/common/sqlite_file.h"

namespace trimbot::visual_localization {
namespace {

using sqlite::Exec;
using sqlite::Prepare;
using sqlite::SqlError;
using sqlite::Statement;
using sqlite::Step;

void BindRow(sqlite3_stmt* statement, int index, const cv::Mat& row) {
  sqlite3_bind_blob(statement, index, row.ptr(), static_cast<int>(row.total() * row.elemSize()), SQLITE_TRANSIENT);
}

cv::Mat BlobRow(sqlite3_stmt* statement, int column, int width) {
  const int bytes = sqlite3_column_bytes(statement, column);
  if (bytes != width * static_cast<int>(sizeof(float))) throw SqlError("a descriptor blob has the wrong size");
  cv::Mat row(1, width, CV_32F);
  std::memcpy(row.ptr(), sqlite3_column_blob(statement, column), static_cast<std::size_t>(bytes));
  return row;
}

void WriteSchema(sqlite3* db, const VisualMap& map) {
  Exec(db,
       "CREATE TABLE keyframes(id INTEGER PRIMARY KEY, stamp REAL, x REAL, y REAL, z REAL,"
       " qw REAL, qx REAL, qy REAL, qz REAL);"
       "CREATE TABLE points(id INTEGER PRIMARY KEY, x REAL, y REAL, z REAL, descriptor BLOB NOT NULL);"
       "CREATE TABLE observations(keyframe INTEGER, camera INTEGER, point INTEGER, u REAL, v REAL);"
       "CREATE TABLE vocabulary(word INTEGER PRIMARY KEY, centroid BLOB NOT NULL);");
  sqlite::WriteMeta(db, {{"format", "trimbot visual map"},
                         {"version", std::to_string(kMapFormatVersion)},
                         {"garden", map.garden},
                         {"rig_signature", map.rig_signature},
                         {"descriptor", ToString(map.descriptor)},
                         {"descriptor_size", std::to_string(map.descriptors.cols)},
                         {"builder", map.builder},
                         {"appearance_version", std::to_string(map.appearance_version)}});
}

void WriteRows(sqlite3* db, const VisualMap& map) {
  Statement keyframe = Prepare(db, "INSERT INTO keyframes VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?)");
  for (const auto& k : map.keyframes) {
    const Eigen::Quaterniond q(k.T_map_base.linear());
    const Eigen::Vector3d t = k.T_map_base.translation();
    sqlite3_bind_int(keyframe.get(), 1, k.id);
    const double values[] = {k.stamp, t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z()};
    for (int i = 0; i < 8; ++i) sqlite3_bind_double(keyframe.get(), i + 2, values[i]);
    Step(db, keyframe.get());
  }
  Statement point = Prepare(db, "INSERT INTO points VALUES(?, ?, ?, ?, ?)");
  for (std::size_t i = 0; i < map.points.size(); ++i) {
    sqlite3_bind_int(point.get(), 1, static_cast<int>(i));
    for (int k = 0; k < 3; ++k) sqlite3_bind_double(point.get(), k + 2, map.points[i](k));
    BindRow(point.get(), 5, map.descriptors.row(static_cast<int>(i)));
    Step(db, point.get());
  }
  Statement observation = Prepare(db, "INSERT INTO observations VALUES(?, ?, ?, ?, ?)");
  for (const auto& o : map.observations) {
    sqlite3_bind_int(observation.get(), 1, o.keyframe);
    sqlite3_bind_int(observation.get(), 2, o.camera);
    sqlite3_bind_int(observation.get(), 3, o.point);
    sqlite3_bind_double(observation.get(), 4, o.pixel.x());
    sqlite3_bind_double(observation.get(), 5, o.pixel.y());
    Step(db, observation.get());
  }
  Statement word = Prepare(db, "INSERT INTO vocabulary VALUES(?, ?)");
  for (int w = 0; w < map.vocabulary.rows; ++w) {
    sqlite3_bind_int(word.get(), 1, w);
    BindRow(word.get(), 2, map.vocabulary.row(w));
    Step(db, word.get());
  }
}

using sqlite::Meta;

void ReadRows(sqlite3* db, int descriptor_size, VisualMap* map) {
  Statement keyframes = Prepare(db, "SELECT id, stamp, x, y, z, qw, qx, qy, qz FROM keyframes ORDER BY id");
  while (sqlite3_step(keyframes.get()) == SQLITE_ROW) {
    MapKeyframe k;
    k.id = sqlite3_column_int(keyframes.get(), 0);
    k.stamp = sqlite3_column_double(keyframes.get(), 1);
    double v[7];
    for (int i = 0; i < 7; ++i) v[i] = sqlite3_column_double(keyframes.get(), i + 2);
    k.T_map_base.translation() << v[0], v[1], v[2];
    k.T_map_base.linear() = Eigen::Quaterniond(v[3], v[4], v[5], v[6]).normalized().toRotationMatrix();
    map->keyframes.push_back(k);
  }
  Statement points = Prepare(db, "SELECT id, x, y, z, descriptor FROM points ORDER BY id");
  std::vector<cv::Mat> rows;
  while (sqlite3_step(points.get()) == SQLITE_ROW) {
    if (sqlite3_column_int(points.get(), 0) != static_cast<int>(map->points.size()))
      throw SqlError("point ids have gaps");
    map->points.emplace_back(sqlite3_column_double(points.get(), 1), sqlite3_column_double(points.get(), 2),
                             sqlite3_column_double(points.get(), 3));
    rows.push_back(BlobRow(points.get(), 4, descriptor_size));
  }
  if (!rows.empty()) cv::vconcat(rows, map->descriptors);
  Statement observations = Prepare(db, "SELECT keyframe, camera, point, u, v FROM observations");
  while (sqlite3_step(observations.get()) == SQLITE_ROW) {
    MapObservation o;
    o.keyframe = sqlite3_column_int(observations.get(), 0);
    o.camera = sqlite3_column_int(observations.get(), 1);
    o.point = sqlite3_column_int(observations.get(), 2);
    o.pixel = {sqlite3_column_double(observations.get(), 3), sqlite3_column_double(observations.get(), 4)};
    if (o.point < 0 || o.point >= static_cast<int>(map->points.size())) throw SqlError("an observation of no point");
    map->observations.push_back(o);
  }
  Statement words = Prepare(db, "SELECT word, centroid FROM vocabulary ORDER BY word");
  std::vector<cv::Mat> centroids;
  while (sqlite3_step(words.get()) == SQLITE_ROW) centroids.push_back(BlobRow(words.get(), 1, descriptor_size));
  if (!centroids.empty()) cv::vconcat(centroids, map->vocabulary);
}

}  // namespace

void VisualMap::Save(const std::string& path) const {
  sqlite::WriteAtomically(path, [this](sqlite3* db) {
    WriteSchema(db, *this);
    WriteRows(db, *this);
  });
}

VisualMap VisualMap::Load(const std::string& path, const std::string& expected_garden,
                          const std::string& expected_rig_signature, std::optional<Descriptor> expected_descriptor) {
  const sqlite::Database db = sqlite::OpenReadOnly(path, "map file");
  VisualMap map;
  try {
    if (Meta(db.get(), "format") != "trimbot visual map") throw SqlError("not a trimbot visual map");
    const std::string version = Meta(db.get(), "version");
    if (version != std::to_string(kMapFormatVersion)) {
      throw InputError(path, "map format version " + version + ", this build reads version " +
                                 std::to_string(kMapFormatVersion) + " (rebuild the map with `trimbot map build`)");
    }
    map.garden = Meta(db.get(), "garden");
    map.rig_signature = Meta(db.get(), "rig_signature");
    map.descriptor = DescriptorFromString(Meta(db.get(), "descriptor"));
    map.builder = Meta(db.get(), "builder");
    map.appearance_version = std::stoi(Meta(db.get(), "appearance_version"));
    ReadRows(db.get(), std::stoi(Meta(db.get(), "descriptor_size")), &map);
    if (map.points.empty()) throw SqlError("the map has no points");
    if (map.vocabulary.empty()) throw SqlError("the map has points but no vocabulary");
  } catch (const SqlError& e) {
    throw InputError(path, std::string("not a valid map file (") + e.what() + ")");
  } catch (const std::logic_error& e) {
    throw InputError(path, std::string("not a valid map file (") + e.what() + ")");
  }
  if (!expected_garden.empty() && map.garden != expected_garden) {
    throw InputError(path,
                     "the map was made in garden '" + map.garden + "', the robot is in '" + expected_garden + "'");
  }
  if (!expected_rig_signature.empty() && map.rig_signature != expected_rig_signature) {
    throw InputError(path, "the map was made with another camera rig (signature " + map.rig_signature + ", this rig " +
                               expected_rig_signature + ")");
  }
  if (expected_descriptor && map.descriptor != *expected_descriptor) {
    throw InputError(path, std::string("the map's descriptor is ") + ToString(map.descriptor) + ", the localizer's " +
                               ToString(*expected_descriptor) + " (build the map with the same descriptor)");
  }
  return map;
}

std::string RigSignature(const robot::CameraRig& rig) {
  std::ostringstream text;
  text << std::fixed;
  for (const auto& camera : rig.cameras()) {
    const auto& k = camera.intrinsics;
    text << std::setprecision(2) << k.width << ' ' << k.height << ' ' << k.fx << ' ' << k.fy << ' ' << k.cx << ' '
         << k.cy << std::setprecision(4) << ' ' << k.k1 << ' ' << k.k2 << ' ' << k.p1 << ' ' << k.p2;
    const Eigen::Matrix4d T = camera.T_base_camera.matrix();
    for (int i = 0; i < 12; ++i) text << ' ' << std::setprecision(4) << T(i % 3, i / 3);
  }
  std::ostringstream hex;
  hex << std::hex << std::setw(16) << std::setfill('0') << StreamSeed(0, text.str());
  return hex.str();
}

}  // namespace trimbot::visual_localization
