#include "trimbot/garden/garden.h"

#include <cmath>
#include <filesystem>
#include <set>

#include "trimbot/common/input_error.h"
#include "trimbot/common/yaml_reader.h"

namespace trimbot::garden {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

Shape ParseShape(const YamlMap& map) {
  const std::string shape = map.String("shape");
  if (shape == "box") return Shape::kBox;
  if (shape == "cylinder") return Shape::kCylinder;
  if (shape == "ellipsoid") return Shape::kEllipsoid;
  map.Fail("shape", "unknown shape '" + shape + "' (box, cylinder, ellipsoid)");
}

}  // namespace

Garden Garden::Load(const std::string& path) {
  const YamlMap root = YamlMap::LoadFile(path);
  Garden garden;
  garden.source = path;
  garden.name = root.String("name");
  const auto size = root.Doubles("size", 2);
  garden.size = {size[0], size[1]};
  if (!(garden.size.x() > 0 && garden.size.y() > 0)) root.Fail("size", "must be positive");
  if (root.Has("centre")) {
    const auto centre = root.Doubles("centre", 2);
    garden.centre = {centre[0], centre[1]};
  }
  const std::string ground = root.String("ground");
  const auto surface = SurfaceFromString(ground);
  if (!surface) root.Fail("ground", "unknown surface '" + ground + "' (grass, gravel, pavement)");
  garden.ground = *surface;

  if (root.Has("sun")) {
    const YamlMap sun = root.Map("sun");
    garden.sun.azimuth = sun.Double("azimuth_deg", garden.sun.azimuth / kDegToRad) * kDegToRad;
    garden.sun.elevation = sun.Double("elevation_deg", garden.sun.elevation / kDegToRad) * kDegToRad;
    garden.sun.intensity = sun.Double("intensity", garden.sun.intensity);
    if (sun.Has("colour")) garden.sun.colour = sun.Vector3("colour");
    garden.sun.shadows = sun.Bool("shadows", garden.sun.shadows);
    if (garden.sun.elevation <= 0.0 || garden.sun.elevation > M_PI / 2) sun.Fail("elevation_deg", "must be in (0, 90]");
    sun.RejectUnknownKeys();
  }

  std::set<int> ids;
  for (const YamlMap& item : root.MapList("objects")) {
    GardenObject object;
    object.id = item.Int("id");
    if (object.id < 1 || object.id > kMaxGardenObjectId) {
      item.Fail("id", "must be in 1.." + std::to_string(kMaxGardenObjectId));
    }
    if (!ids.insert(object.id).second) item.Fail("id", "duplicate id " + std::to_string(object.id));
    const std::string class_name = item.String("class");
    const auto object_class = ObjectClassFromString(class_name);
    if (!object_class || *object_class == ObjectClass::kNone || *object_class == ObjectClass::kGround ||
        *object_class == ObjectClass::kRobot) {
      item.Fail("class", "unknown object class '" + class_name +
                             "' (topiary, rose, hedge, tree, trunk, fence, obstacle)");
    }
    object.object_class = *object_class;
    object.shape = ParseShape(item);
    object.size = item.Vector3("size");
    if (!(object.size.minCoeff() > 0.0)) item.Fail("size", "all extents must be positive");
    const auto position = item.Doubles("position", 2);
    object.position = {position[0], position[1]};
    object.base_height = item.Double("base_height", 0.0);
    object.yaw = item.Double("yaw_deg", 0.0) * kDegToRad;
    item.RejectUnknownKeys();
    garden.objects.push_back(object);
  }
  root.RejectUnknownKeys();
  return garden;
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
