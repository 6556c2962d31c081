#pragma once
// A garden as data: lawn, paths and beds, and objects with their class and shape. Gardens are YAML
// files (garden_scenes/gardens/*.yaml); the simulator turns them into MuJoCo geometry. What varies
// from run to run (time of day, season) is in Conditions, not in the garden.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "trimbot/garden/object_class.h"

namespace trimbot {
class YamlMap;
}

namespace trimbot::garden {

enum class Shape { kBox, kCylinder, kEllipsoid };

struct GardenObject {
  int id = 0;  // unique in the garden, 1..kMaxGardenObjectId
  ObjectClass object_class = ObjectClass::kObstacle;
  Shape shape = Shape::kBox;                           // the trimmed / nominal shape
  Eigen::Vector3d size = Eigen::Vector3d::Ones();      // m, full extent along x, y, z before yaw
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // m, centre of the footprint in the map frame
  double base_height = 0.0;                            // m above the ground where the object starts
  double yaw = 0.0;                                    // rad about z
};

// A rectangle of another ground surface (a path or a bed), flush with the lawn.
struct GroundPatch {
  Surface surface = Surface::kGravel;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d size = Eigen::Vector2d::Ones();  // m, along the patch's own x and y
  double yaw = 0.0;
};

// The largest garden extent (and object extent or coordinate) a garden file may give, m: the
// occupancy maps and renders grow with the square of it.
constexpr double kMaxGardenExtent = 200.0;

struct Garden {
  std::string name;
  std::string source;                                // file it was read from
  Eigen::Vector2d size = Eigen::Vector2d(10, 10);    // m, ground extent
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  // m, ground centre in the map frame
  Surface ground = Surface::kGrass;
  double latitude = 52.0 * M_PI / 180.0;  // rad (Wageningen by default), for the sun's path
  double north = M_PI / 2;                // rad, direction of north in the map frame (from +x, CCW)
  // Seeds the garden's look - textures, leaf clumps, outgrowth - so every run in this garden sees
  // the same garden (a run's own seed drives only sensor noise, faults and dynamics). The file's
  // `seed:`, or else one derived from the garden's name.
  std::uint64_t appearance_seed = 0;
  std::vector<GroundPatch> paths;
  std::vector<GardenObject> objects;

  // Throws InputError naming the file, line and key.
  static Garden Load(const std::string& path);
  std::string ToYaml() const;
  // Ground surface at a map point: the last path containing it, else the lawn.
  Surface SurfaceAt(const Eigen::Vector2d& point) const;
  // Finds garden_scenes/gardens/<name>.yaml, or takes a path to a .yaml file.
  static std::string Resolve(const std::string& name_or_path, const std::string& gardens_dir);
  // Adds objects that are not in the garden file (a scenario's unmapped objects); ids must stay
  // unique (labels and contacts name objects by id): std::invalid_argument naming the id otherwise.
  void AddObjects(const std::vector<GardenObject>& extra);
};

bool IsFoliage(ObjectClass c);

// One object as a garden file writes it ({id, class, shape, size, position, base_height, yaw_deg}).
// Throws InputError naming the file, line and key.
GardenObject ReadGardenObject(const YamlMap& item);

}  // namespace trimbot::garden
