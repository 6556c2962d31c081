#include "trimbot/garden/garden_tools.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <optional>
#include <random>
#include <set>
#include <sstream>

#include "trimbot/common/angles.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/parse_number.h"
#include "trimbot/common/random.h"
#include "trimbot/garden/object_mesh.h"

namespace trimbot::garden {
namespace {

// GardenUI's label families; anything else is refused rather than guessed.
std::optional<ObjectClass> ClassOfLabel(const std::string& label) {
  if (label.rfind("Topiary", 0) == 0) return ObjectClass::kTopiary;
  if (label.rfind("Hedge", 0) == 0) return ObjectClass::kHedge;
  if (label.rfind("Rose", 0) == 0) return ObjectClass::kRose;
  if (label == "Obstacle-Tree") return ObjectClass::kTree;
  if (label == "Obstacle-Trunk") return ObjectClass::kTrunk;
  if (label == "Obstacle-Fence" || label == "Obstacle-Post") return ObjectClass::kFence;
  for (const char* family : {"Obstacle", "Background", "Robot"}) {
    if (label.rfind(family, 0) == 0) return ObjectClass::kObstacle;
  }
  return std::nullopt;
}

// Corners of an object's (or patch's) footprint rectangle in the map frame.
std::vector<Eigen::Vector2d> FootprintCorners(const Eigen::Vector2d& centre, const Eigen::Vector2d& size, double yaw) {
  const Eigen::Rotation2Dd rotation(yaw);
  std::vector<Eigen::Vector2d> corners;
  for (const auto& [sx, sy] : std::vector<std::pair<double, double>>{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    corners.push_back(centre + rotation * Eigen::Vector2d(sx * size.x() / 2, sy * size.y() / 2));
  }
  return corners;
}

// Separating-axis test for two rotated rectangles grown by `margin`.
bool Overlap(const Eigen::Vector2d& c1, const Eigen::Vector2d& s1, double yaw1, const Eigen::Vector2d& c2,
             const Eigen::Vector2d& s2, double yaw2, double margin) {
  const auto a = FootprintCorners(c1, s1 + Eigen::Vector2d::Constant(margin), yaw1);
  const auto b = FootprintCorners(c2, s2 + Eigen::Vector2d::Constant(margin), yaw2);
  for (const double yaw : {yaw1, yaw1 + M_PI / 2, yaw2, yaw2 + M_PI / 2}) {
    const Eigen::Vector2d axis(std::cos(yaw), std::sin(yaw));
    double a_min = 1e9, a_max = -1e9, b_min = 1e9, b_max = -1e9;
    for (const auto& p : a) a_min = std::min(a_min, p.dot(axis)), a_max = std::max(a_max, p.dot(axis));
    for (const auto& p : b) b_min = std::min(b_min, p.dot(axis)), b_max = std::max(b_max, p.dot(axis));
    if (a_max < b_min || b_max < a_min) return false;
  }
  return true;
}

}  // namespace

Garden ImportGardenUiCsv(const std::string& path, double ground_z) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "file not found");
  Garden garden;
  garden.source = path;
  std::string line;
  int line_number = 0;
  Eigen::Vector2d low(1e9, 1e9), high(-1e9, -1e9);
  std::set<int> ids;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty() || line[0] == '#' || line.rfind("id,", 0) == 0) continue;
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    if (fields.size() != 10) {
      throw InputError(
          path, "line " + std::to_string(line_number) + ": expected 10 fields, got " + std::to_string(fields.size()));
    }
    GardenObject object;
    const auto fail = [&](const std::string& problem) {
      throw InputError(path, "line " + std::to_string(line_number) + ": " + problem);
    };
    const auto number = [&](int field, const char* name, double lo, double hi) {
      const auto value = ParseFiniteNumber(fields[static_cast<std::size_t>(field)]);
      if (!value || *value < lo || *value > hi) {
        std::ostringstream expected;
        expected << name << " '" << fields[static_cast<std::size_t>(field)] << "' is not a number in [" << lo << ", "
                 << hi << "]";
        fail(expected.str());
      }
      return *value;
    };
    const auto id = ParseInteger(fields[0], 1, kMaxGardenObjectId);
    if (!id) fail("id '" + fields[0] + "' is not a whole number in 1.." + std::to_string(kMaxGardenObjectId));
    object.id = static_cast<int>(*id);
    if (!ids.insert(object.id).second) fail("duplicate id " + std::to_string(object.id));
    object.size = {number(3, "size_x", 1e-3, kMaxGardenExtent), number(4, "size_y", 1e-3, kMaxGardenExtent),
                   number(5, "size_z", 1e-3, kMaxGardenExtent)};
    object.position = {number(6, "pos_x", -kMaxGardenExtent, kMaxGardenExtent),
                       number(7, "pos_y", -kMaxGardenExtent, kMaxGardenExtent)};
    object.base_height = number(8, "pos_z", -kMaxGardenExtent, kMaxGardenExtent) - ground_z;
    object.yaw = number(9, "yaw_deg", -360.0, 360.0) * kDegToRad;
    const auto object_class = ClassOfLabel(fields[1]);
    if (!object_class)
      fail("unknown label '" + fields[1] + "' (Topiary-*, Hedge-*, Rose-*, Obstacle-*, Background-*, Robot-*)");
    object.object_class = *object_class;
    // GardenUI boxes are bounding boxes: topiary and tree crowns are round, roses and trunks cylinders.
    switch (object.object_class) {
      case ObjectClass::kTopiary:
      case ObjectClass::kTree:
        object.shape = Shape::kEllipsoid;
        break;
      case ObjectClass::kRose:
      case ObjectClass::kTrunk:
        object.shape = Shape::kCylinder;
        break;
      default:
        object.shape = Shape::kBox;
        break;
    }
    // The boxes were fitted to point clouds whose lowest points lie above the ground (grass hides
    // the base): objects that start low stand on the ground, keeping their tops. Tree crowns stay up.
    if (object.base_height < 0.3) {
      object.size.z() += object.base_height;  // also for boxes reaching a little below the ground
      object.base_height = 0.0;
    }
    if (!(object.size.z() > 0.0)) {
      fail("object " + std::to_string(object.id) + " ends below the ground (is --ground-z the file's ground level?)");
    }
    low = low.cwiseMin(object.position - object.size.head<2>() / 2);
    high = high.cwiseMax(object.position + object.size.head<2>() / 2);
    garden.objects.push_back(object);
  }
  if (garden.objects.empty()) throw InputError(path, "no objects");
  garden.centre = (low + high) / 2;
  garden.size = (high - low) + Eigen::Vector2d(2.0, 2.0);
  return garden;
}

namespace {

// Draws a garden's layout from one random stream in a fixed order (paths, trees, hedges, corridors, topiary,
// roses, obstacles, fence), so the same seed gives the same garden.
class GardenGenerator {
 public:
  GardenGenerator(const GeneratorParameters& p, Garden* garden)
      : p_(p), garden_(*garden), rng_(MakeRng(p.seed, "garden_generator")), half_(p.size / 2) {}

  // Paths: straight strips across the garden, alternately along x and y.
  void AddPaths() {
    const Surface path_surfaces[] = {Surface::kGravel, Surface::kPavement, Surface::kSoil};
    for (int i = 0; i < p_.paths; ++i) {
      GroundPatch patch;
      patch.surface = path_surfaces[i % 3];
      const bool along_x = i % 2 == 0;
      const double width = uniform(0.8, 1.5);
      patch.size = along_x ? Eigen::Vector2d(p_.size.x() * uniform(0.5, 0.9), width)
                           : Eigen::Vector2d(width, p_.size.y() * uniform(0.5, 0.9));
      patch.centre = {uniform(-half_.x() + patch.size.x() / 2, half_.x() - patch.size.x() / 2),
                      uniform(-half_.y() + patch.size.y() / 2, half_.y() - patch.size.y() / 2)};
      garden_.paths.push_back(patch);
    }
  }

  // A tree: a trunk placed with the robot's clearance and a crown on it.
  void AddTrees() {
    for (int i = 0; i < p_.trees; ++i) {
      const double crown = uniform(2.4, 3.6);
      GardenObject trunk = Make(ObjectClass::kTrunk, Shape::kCylinder, {0.3, 0.3, uniform(1.4, 1.8)});
      if (GardenObject* placed = Place(trunk, p_.robot_clearance)) {
        GardenObject tree =
            Make(ObjectClass::kTree, Shape::kEllipsoid, {crown, crown * uniform(0.9, 1.1), uniform(2.5, 3.4)});
        tree.position = placed->position;
        tree.base_height = placed->size.z() - 0.3;
        tree.id = next_id_++;
        garden_.objects.push_back(tree);
      }
    }
  }

  void AddHedgesBushesAndObstacles() {
    for (int i = 0; i < p_.hedges; ++i) {
      const double length = uniform(2.0, 5.0);
      Place(Make(ObjectClass::kHedge, Shape::kBox, {length, uniform(0.5, 0.8), uniform(0.4, 1.4)},
                 UniformUnit(rng_) < 0.5 ? 0.0 : M_PI / 2),
            p_.robot_clearance);
    }
    for (int i = 0; i < p_.corridors; ++i) AddCorridor();
    for (int i = 0; i < p_.topiary; ++i) {
      const double d = uniform(0.6, 0.9);
      const double u = UniformUnit(rng_);
      const Shape shape = u < p_.topiary_box_share                               ? Shape::kBox
                          : u < p_.topiary_box_share + p_.topiary_cylinder_share ? Shape::kCylinder
                                                                                 : Shape::kEllipsoid;
      // A cylinder's plan is round (the foliage and the fit take its x and y as one diameter).
      const double across = shape == Shape::kCylinder ? d : d * uniform(0.9, 1.1);
      Place(Make(ObjectClass::kTopiary, shape, {d, across, d * uniform(0.6, 1.0)}), p_.robot_clearance);
    }
    for (int i = 0; i < p_.roses; ++i) {
      const double d = uniform(0.5, 0.8);
      Place(Make(ObjectClass::kRose, Shape::kCylinder, {d, d, uniform(0.5, 0.8)}), p_.robot_clearance);
    }
    for (int i = 0; i < p_.obstacles; ++i) {
      Place(Make(ObjectClass::kObstacle, Shape::kBox, {uniform(0.3, 1.2), uniform(0.3, 1.0), uniform(0.3, 0.9)},
                 uniform(0.0, M_PI)),
            p_.robot_clearance);
    }
  }

  // Two parallel hedges and the corridor between them, placed as one block (so nothing else is put
  // inside the corridor), then split into the two hedges.
  void AddCorridor() {
    const double length = uniform(2.5, 4.5), thickness = uniform(0.5, 0.7), height = uniform(0.8, 1.4);
    const double gap = uniform(p_.corridor_width.x(), p_.corridor_width.y());
    const double yaw = UniformUnit(rng_) < 0.5 ? 0.0 : M_PI / 2;
    GardenObject block = Make(ObjectClass::kHedge, Shape::kBox, {length, 2.0 * thickness + gap, height}, yaw);
    GardenObject* placed = Place(block, p_.robot_clearance);
    if (placed == nullptr) return;
    const Eigen::Vector2d centre = placed->position;
    const Eigen::Vector2d across(-std::sin(yaw), std::cos(yaw));
    garden_.objects.pop_back();
    --next_id_;
    for (const double side : {-1.0, 1.0}) {
      GardenObject hedge = Make(ObjectClass::kHedge, Shape::kBox, {length, thickness, height}, yaw);
      hedge.position = centre + side * 0.5 * (gap + thickness) * across;
      hedge.id = next_id_++;
      garden_.objects.push_back(hedge);
    }
  }

  void AddFence() {
    if (!p_.fence) return;
    for (int side = 0; side < 4; ++side) {
      const bool along_x = side < 2;
      const double offset = (side % 2 == 0 ? -1 : 1) * (along_x ? half_.y() : half_.x());
      GardenObject fence =
          Make(ObjectClass::kFence, Shape::kBox,
               along_x ? Eigen::Vector3d(p_.size.x(), 0.1, 0.8) : Eigen::Vector3d(0.1, p_.size.y(), 0.8));
      fence.position = along_x ? Eigen::Vector2d(0.0, offset) : Eigen::Vector2d(offset, 0.0);
      fence.id = next_id_++;
      garden_.objects.push_back(fence);
    }
  }

 private:
  double uniform(double lo, double hi) { return lo + (hi - lo) * UniformUnit(rng_); }

  static GardenObject Make(ObjectClass c, Shape shape, const Eigen::Vector3d& size, double yaw = 0.0) {
    GardenObject o;
    o.object_class = c;
    o.shape = shape;
    o.size = size;
    o.yaw = yaw;
    return o;
  }

  // Places an object where it overlaps nothing else, with the robot's clearance, and fence_clearance
  // inside the edge; gives up after a number of tries, or at once when the garden is too small for
  // it (a crowded garden just gets fewer objects).
  GardenObject* Place(GardenObject object, double margin) {
    const double edge = p_.fence_clearance;
    if ((object.size.head<2>() / 2 + Eigen::Vector2d::Constant(edge) - half_).maxCoeff() > 0.0) return nullptr;
    for (int attempt = 0; attempt < 200; ++attempt) {
      object.position = {uniform(-half_.x() + object.size.x() / 2 + edge, half_.x() - object.size.x() / 2 - edge),
                         uniform(-half_.y() + object.size.y() / 2 + edge, half_.y() - object.size.y() / 2 - edge)};
      bool free = true;
      for (const auto& other : garden_.objects) {
        if (other.object_class == ObjectClass::kFence) continue;
        free = free && !Overlap(object.position, object.size.head<2>(), object.yaw, other.position,
                                other.size.head<2>(), other.yaw, margin);
      }
      for (const auto& path : garden_.paths) {
        free =
            free && !Overlap(object.position, object.size.head<2>(), object.yaw, path.centre, path.size, path.yaw, 0.1);
      }
      if (free) {
        object.id = next_id_++;
        garden_.objects.push_back(object);
        return &garden_.objects.back();
      }
    }
    return nullptr;
  }

  const GeneratorParameters& p_;
  Garden& garden_;
  Rng rng_;
  Eigen::Vector2d half_;
  int next_id_ = 1;
};

}  // namespace

Garden GenerateGarden(const GeneratorParameters& p) {
  Garden garden;
  garden.name = "generated_" + std::to_string(p.seed);
  garden.appearance_seed = StreamSeed(p.seed, "garden_appearance") >> 33;  // fits the file's 31-bit seed
  garden.size = p.size + Eigen::Vector2d(2.0, 2.0);
  garden.centre = Eigen::Vector2d::Zero();
  GardenGenerator generator(p, &garden);
  generator.AddPaths();
  generator.AddTrees();
  generator.AddHedgesBushesAndObstacles();
  generator.AddFence();
  return garden;
}

cv::Point OccupancyMap::Cell(const Eigen::Vector2d& point) const {
  const int column = static_cast<int>(std::floor((point.x() - origin.x()) / resolution));
  const int row_from_bottom = static_cast<int>(std::floor((point.y() - origin.y()) / resolution));
  return {column, occupied.rows - 1 - row_from_bottom};
}

Eigen::Vector2d OccupancyMap::CellCentre(const cv::Point& cell) const {
  return origin + resolution * Eigen::Vector2d(cell.x + 0.5, occupied.rows - 1 - cell.y + 0.5);
}

double FootprintScaleBelow(const GardenObject& object, double clearance) {
  if (object.base_height >= clearance) return 0.0;
  if (object.shape != Shape::kEllipsoid) return 1.0;
  const double c = object.size.z() / 2, centre = object.base_height + c;
  if (clearance >= centre) return 1.0;
  const double u = (centre - clearance) / c;
  return std::sqrt(std::max(0.0, 1.0 - u * u));
}

namespace {

bool InFootprint(const GardenObject& object, const Eigen::Vector2d& point, double scale = 1.0) {
  const Eigen::Vector2d local = Eigen::Rotation2Dd(-object.yaw) * (point - object.position);
  const Eigen::Vector2d half = scale * object.size.head<2>() / 2;
  if (object.shape == Shape::kBox) return std::abs(local.x()) <= half.x() && std::abs(local.y()) <= half.y();
  return (local.x() / half.x()) * (local.x() / half.x()) + (local.y() / half.y()) * (local.y() / half.y()) <= 1.0;
}

}  // namespace

std::vector<Eigen::Vector2d> FootprintBoundary(const GardenObject& object, double scale, double spacing) {
  const Eigen::Vector2d half = scale * object.size.head<2>() / 2;
  const Eigen::Rotation2Dd rotation(object.yaw);
  std::vector<Eigen::Vector2d> points;
  if (object.shape == Shape::kBox) {
    const Eigen::Vector2d corners[4] = {{-half.x(), -half.y()}, {half.x(), -half.y()}, half, {-half.x(), half.y()}};
    for (int side = 0; side < 4; ++side) {
      const Eigen::Vector2d a = corners[side], b = corners[(side + 1) % 4];
      const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing)));
      for (int k = 0; k < steps; ++k) {
        points.push_back(object.position + rotation * (a + (static_cast<double>(k) / steps) * (b - a)));
      }
    }
    return points;
  }
  // An ellipse: a step in its angle moves a boundary point at most the longer semi-axis times it.
  const int steps = std::max(8, static_cast<int>(std::ceil(2.0 * M_PI * half.maxCoeff() / spacing)));
  for (int k = 0; k < steps; ++k) {
    const double angle = 2.0 * M_PI * k / steps;
    points.push_back(object.position +
                     rotation * Eigen::Vector2d(half.x() * std::cos(angle), half.y() * std::sin(angle)));
  }
  return points;
}

const GardenObject* ObjectAt(const Garden& garden, const Eigen::Vector2d& point, double clearance) {
  for (const auto& object : garden.objects) {
    const double scale = FootprintScaleBelow(object, clearance);
    if (scale > 0.0 && InFootprint(object, point, scale)) return &object;
  }
  return nullptr;
}

namespace {

// Marks the cells whose centre lies in the object's footprint (scaled by `scale`): the occupied
// squares neither grow nor shrink a footprint on average, where marking every cell a footprint
// touches grows each object by half a cell, up to a whole one, all round (5 cm of the 10 cm a side
// that a gap 0.2 m wider than the base leaves). Margins for a survey's errors are the planner's
// (its clearance wall and cost), not the map's. A band narrower than a cell's diagonal can fall
// between the cells' centres, so an object that thin (a fence) gets the line of cells along its
// longer axis instead.
void MarkFootprint(const GardenObject& object, double scale, OccupancyMap& map) {
  const Eigen::Vector2d half = scale * object.size.head<2>() / 2;
  const Eigen::Vector2d reach = Eigen::Vector2d::Constant(half.norm());
  const cv::Point low = map.Cell(object.position - reach), high = map.Cell(object.position + reach);
  for (int row = std::max(0, high.y); row <= std::min(map.occupied.rows - 1, low.y); ++row) {
    for (int column = std::max(0, low.x); column <= std::min(map.occupied.cols - 1, high.x); ++column) {
      if (InFootprint(object, map.CellCentre({column, row}), scale)) map.occupied.at<uchar>(row, column) = 255;
    }
  }
  if (2.0 * half.minCoeff() >= std::sqrt(2.0) * map.resolution) return;
  const Eigen::Vector2d axis = Eigen::Rotation2Dd(object.yaw) *
                               (half.x() >= half.y() ? Eigen::Vector2d(half.x(), 0.0) : Eigen::Vector2d(0.0, half.y()));
  cv::line(map.occupied, map.Cell(object.position - axis), map.Cell(object.position + axis), cv::Scalar(255));
}

}  // namespace

OccupancyMap MakeOccupancyMap(const Garden& garden, double resolution, double clearance) {
  OccupancyMap map;
  map.resolution = resolution;
  map.origin = garden.centre - garden.size / 2;
  const int columns = static_cast<int>(std::ceil(garden.size.x() / resolution));
  const int rows = static_cast<int>(std::ceil(garden.size.y() / resolution));
  map.occupied = cv::Mat::zeros(rows, columns, CV_8U);
  for (const auto& object : garden.objects) {
    const double scale = FootprintScaleBelow(object, clearance);
    if (scale > 0.0) MarkFootprint(object, scale, map);
  }
  return map;
}

void WriteOccupancyMap(const OccupancyMap& map, const std::string& dir, const std::string& name) {
  // map_server convention: dark = occupied.
  cv::Mat image = 255 - map.occupied;
  std::vector<uchar> png;
  cv::imencode(".png", image, png);
  WriteFileAtomically(dir + "/" + name + ".png", std::string(png.begin(), png.end()));
  std::ostringstream yaml;
  yaml << std::setprecision(10) << "image: " << name << ".png\n"
       << "resolution: " << map.resolution << "\n"
       << "origin: [" << map.origin.x() << ", " << map.origin.y() << ", 0.0]\n"
       << "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  WriteFileAtomically(dir + "/" + name + ".yaml", yaml.str());
}

std::vector<SurfaceSample> SampleSurfaces(const Garden& garden, double growth, double points_per_m2) {
  Rng rng = MakeRng(garden.appearance_seed, "ground_truth_ply");
  std::vector<SurfaceSample> samples;
  auto sample_mesh = [&](const Mesh& mesh, const Eigen::Matrix4d& pose, ObjectClass c, int id) {
    for (const auto& f : mesh.faces) {
      const Eigen::Vector3d a = mesh.vertices[f[0]], b = mesh.vertices[f[1]], d = mesh.vertices[f[2]];
      const double area = 0.5 * (b - a).cross(d - a).norm();
      // Whole expected count plus a random remainder keeps the density exact on average.
      const double expected = area * points_per_m2;
      const int n = static_cast<int>(expected) + (UniformUnit(rng) < expected - std::floor(expected) ? 1 : 0);
      for (int k = 0; k < n; ++k) {
        double u = UniformUnit(rng), v = UniformUnit(rng);
        if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
        const Eigen::Vector3d local = a + u * (b - a) + v * (d - a);
        samples.push_back({(pose * local.homogeneous()).head<3>(), c, id});
      }
    }
  };
  Mesh lawn;
  const Eigen::Vector2d low = garden.centre - garden.size / 2, high = garden.centre + garden.size / 2;
  lawn.vertices = {{low.x(), low.y(), 0}, {high.x(), low.y(), 0}, {high.x(), high.y(), 0}, {low.x(), high.y(), 0}};
  lawn.faces = {{0, 1, 2}, {0, 2, 3}};
  sample_mesh(lawn, Eigen::Matrix4d::Identity(), ObjectClass::kGround, kGroundObjectId);
  for (const auto& object : garden.objects) {
    sample_mesh(ObjectMesh(object, garden.appearance_seed, growth), ObjectPose(object), object.object_class, object.id);
  }
  return samples;
}

void WriteGroundTruthPly(const Garden& garden, double growth, double points_per_m2, const std::string& path) {
  const std::vector<SurfaceSample> samples = SampleSurfaces(garden, growth, points_per_m2);
  std::ostringstream ply;
  ply << std::setprecision(6) << "ply\nformat ascii 1.0\ncomment garden " << garden.name << " seed "
      << garden.appearance_seed << " growth " << growth << "\nelement vertex " << samples.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar class\nproperty ushort object\n"
         "end_header\n";
  for (const auto& s : samples) {
    ply << s.position.x() << ' ' << s.position.y() << ' ' << s.position.z() << ' ' << static_cast<int>(s.object_class)
        << ' ' << s.object << '\n';
  }
  WriteFileAtomically(path, ply.str());
}

}  // namespace trimbot::garden
