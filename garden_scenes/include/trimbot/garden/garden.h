#pragma once
// A garden as data: ground, objects with their class and shape, and the sun. Gardens are YAML files
// (garden_scenes/gardens/*.yaml); the simulator turns them into MuJoCo geometry.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "trimbot/garden/object_class.h"

namespace trimbot::garden {

enum class Shape { kBox, kCylinder, kEllipsoid };

struct GardenObject {
  int id = 0;                                       // unique in the garden, 1..kMaxGardenObjectId
  ObjectClass object_class = ObjectClass::kObstacle;
  Shape shape = Shape::kBox;
  Eigen::Vector3d size = Eigen::Vector3d::Ones();   // m, full extent along x, y, z before yaw
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // m, centre of the footprint in the map frame
  double base_height = 0.0;                         // m above the ground where the object starts
  double yaw = 0.0;                                 // rad about z
};

struct Sun {
  double azimuth = 2.4;      // rad, direction the light comes from, counter-clockwise from +x
  double elevation = 0.8;    // rad above the horizon
  double intensity = 0.8;    // diffuse, 0..1
  Eigen::Vector3d colour = Eigen::Vector3d(1.0, 0.97, 0.9);
  bool shadows = true;
};

struct Garden {
  std::string name;
  std::string source;                       // file it was read from
  Eigen::Vector2d size = Eigen::Vector2d(10, 10);     // m, ground extent
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();   // m, ground centre in the map frame
  Surface ground = Surface::kGrass;
  Sun sun;
  std::vector<GardenObject> objects;

  // Throws InputError naming the file, line and key.
  static Garden Load(const std::string& path);
  // Finds garden_scenes/gardens/<name>.yaml, or takes a path to a .yaml file.
  static std::string Resolve(const std::string& name_or_path, const std::string& gardens_dir);
};

}  // namespace trimbot::garden
