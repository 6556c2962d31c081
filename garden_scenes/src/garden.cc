#include "trimbot/garden/garden.h"

#include <stdexcept>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <set>
#include <sstream>

#include "trimbot/common/angles.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/random.h"
#include "trimbot/common/yaml_reader.h"

namespace trimbot::garden {
namespace {

Shape ParseShape(const YamlMap& map) {
  const std::string shape = map.String("shape");
  if (shape == "box") return Shape::kBox;
  if (shape == "cylinder") return Shape::kCylinder;
  if (shape == "ellipsoid") return Shape::kEllipsoid;
  map.Fail("shape", "unknown shape '" + shape + "' (box, cylinder, ellipsoid)");
}

}  // namespace

GardenObject ReadGardenObject(const YamlMap& item) {
  GardenObject object;
  object.id = item.Int("id");
  if (object.id < 1 || object.id > kMaxGardenObjectId) {
    item.Fail("id", "must be in 1.." + std::to_string(kMaxGardenObjectId));
  }
  const std::string class_name = item.String("class");
  const auto object_class = ObjectClassFromString(class_name);
  if (!object_class || *object_class == ObjectClass::kNone || *object_class == ObjectClass::kGround ||
      *object_class == ObjectClass::kRobot) {
    item.Fail("class",
              "unknown object class '" + class_name + "' (topiary, rose, hedge, tree, trunk, fence, obstacle)");
  }
  object.object_class = *object_class;
  object.shape = ParseShape(item);
  const auto size = item.Numbers("size", 3, 1e-3, kMaxGardenExtent, "m");
  object.size = {size[0], size[1], size[2]};
  const auto position = item.Numbers("position", 2, -kMaxGardenExtent, kMaxGardenExtent, "m");
  object.position = {position[0], position[1]};
  object.base_height = item.NumberOr("base_height", 0.0, 0.0, kMaxGardenExtent, "m");
  object.yaw = item.NumberOr("yaw_deg", 0.0, -360.0, 360.0, "deg") * kDegToRad;
  item.RejectUnknownKeys();
  return object;
}

Garden Garden::Load(const std::string& path) {
  const YamlMap root = YamlMap::LoadFile(path);
  Garden garden;
  garden.source = path;
  garden.name = root.Name("name");  // names output files: never a path
  if (root.Has("seed")) {
    const int seed = root.Integer("seed", 0, 2147483647);
    garden.appearance_seed = static_cast<std::uint64_t>(seed);
  } else {
    garden.appearance_seed = StreamSeed(0, "garden/" + garden.name);
  }
  const auto size = root.Numbers("size", 2, 1.0, kMaxGardenExtent, "m");
  garden.size = {size[0], size[1]};
  root.Has("description");  // free text for people
  if (root.Has("centre")) {
    const auto centre = root.Numbers("centre", 2, -kMaxGardenExtent, kMaxGardenExtent, "m");
    garden.centre = {centre[0], centre[1]};
  }
  const std::string ground = root.String("ground");
  const auto surface = SurfaceFromString(ground);
  if (!surface) root.Fail("ground", "unknown surface '" + ground + "' (grass, gravel, pavement, soil)");
  garden.ground = *surface;

  garden.latitude = root.NumberOr("latitude_deg", garden.latitude / kDegToRad, -90.0, 90.0, "deg") * kDegToRad;
  garden.north = root.NumberOr("north_deg", garden.north / kDegToRad, -360.0, 360.0, "deg") * kDegToRad;
  if (root.Has("paths")) {
    for (const YamlMap& item : root.MapList("paths")) {
      GroundPatch patch;
      const std::string surface_name = item.String("surface");
      const auto surface = SurfaceFromString(surface_name);
      if (!surface) item.Fail("surface", "unknown surface '" + surface_name + "' (grass, gravel, pavement, soil)");
      patch.surface = *surface;
      const auto centre = item.Numbers("centre", 2, -kMaxGardenExtent, kMaxGardenExtent, "m");
      const auto size = item.Numbers("size", 2, 1e-3, kMaxGardenExtent, "m");
      patch.centre = {centre[0], centre[1]};
      patch.size = {size[0], size[1]};
      patch.yaw = item.NumberOr("yaw_deg", 0.0, -360.0, 360.0, "deg") * kDegToRad;
      item.RejectUnknownKeys();
      garden.paths.push_back(patch);
    }
  }

  std::set<int> ids;
  for (const YamlMap& item : root.MapList("objects")) {
    const GardenObject object = ReadGardenObject(item);
    if (!ids.insert(object.id).second) item.Fail("id", "duplicate id " + std::to_string(object.id));
    garden.objects.push_back(object);
  }
  root.RejectUnknownKeys();
  return garden;
}

bool IsFoliage(ObjectClass c) {
  return c == ObjectClass::kTopiary || c == ObjectClass::kRose || c == ObjectClass::kHedge || c == ObjectClass::kTree;
}

Surface Garden::SurfaceAt(const Eigen::Vector2d& point) const {
  Surface surface = ground;
  for (const auto& path : paths) {
    const Eigen::Vector2d local = Eigen::Rotation2Dd(-path.yaw) * (point - path.centre);
    if (std::abs(local.x()) <= path.size.x() / 2 && std::abs(local.y()) <= path.size.y() / 2) surface = path.surface;
  }
  return surface;
}

std::string Garden::ToYaml() const {
  std::ostringstream out;
  out << std::setprecision(6);
  auto shape_name = [](Shape shape) {
    return shape == Shape::kBox ? "box" : shape == Shape::kCylinder ? "cylinder" : "ellipsoid";
  };
  out << "name: " << name << "\n"
      << "seed: " << appearance_seed << "\n"
      << "size: [" << size.x() << ", " << size.y() << "]\n"
      << "centre: [" << centre.x() << ", " << centre.y() << "]\n"
      << "ground: " << ToString(ground) << "\n"
      << "latitude_deg: " << latitude / kDegToRad << "\n"
      << "north_deg: " << north / kDegToRad << "\n"
      << "paths:" << (paths.empty() ? " []" : "") << "\n";
  for (const auto& p : paths) {
    out << "  - {surface: " << ToString(p.surface) << ", centre: [" << p.centre.x() << ", " << p.centre.y()
        << "], size: [" << p.size.x() << ", " << p.size.y() << "], yaw_deg: " << p.yaw / kDegToRad << "}\n";
  }
  out << "objects:" << (objects.empty() ? " []" : "") << "\n";
  for (const auto& o : objects) {
    out << "  - {id: " << o.id << ", class: " << ToString(o.object_class) << ", shape: " << shape_name(o.shape)
        << ", size: [" << o.size.x() << ", " << o.size.y() << ", " << o.size.z() << "], position: [" << o.position.x()
        << ", " << o.position.y() << "]";
    if (o.base_height != 0.0) out << ", base_height: " << o.base_height;
    if (o.yaw != 0.0) out << ", yaw_deg: " << o.yaw / kDegToRad;
    out << "}\n";
  }
  return out.str();
}

void Garden::AddObjects(const std::vector<GardenObject>& extra) {
  for (const GardenObject& added : extra) {
    for (const GardenObject& object : objects) {
      if (object.id == added.id) {
        throw std::invalid_argument("object id " + std::to_string(added.id) + " is already used in garden '" + name +
                                    "'");
      }
    }
    objects.push_back(added);
  }
}

std::string Garden::Resolve(const std::string& name_or_path, const std::string& gardens_dir) {
  namespace fs = std::filesystem;
  if (fs::path(name_or_path).extension() == ".yaml") {
    if (!fs::is_regular_file(name_or_path)) throw InputError(name_or_path, "garden file not found");
    return name_or_path;
  }
  const fs::path candidate = fs::path(gardens_dir) / (name_or_path + ".yaml");
  if (fs::is_regular_file(candidate)) return candidate.string();
  std::string known;
  if (fs::is_directory(gardens_dir)) {
    for (const auto& entry : fs::directory_iterator(gardens_dir)) {
      if (entry.path().extension() == ".yaml") known += (known.empty() ? "" : ", ") + entry.path().stem().string();
    }
  }
  throw InputError(candidate.string(), "unknown garden '" + name_or_path + "' (known: " + known + ")");
}

}  // namespace trimbot::garden
