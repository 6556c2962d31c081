#pragma once
// Tools over gardens: import from the TrimBot2020 GardenUI object map (CSV), a seeded generator of
// new gardens, and exports of the 2D occupancy map (map_server) and the ground-truth geometry (PLY).
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

#include "trimbot/garden/garden.h"

namespace trimbot::garden {

// GardenUI CSV (id,label,shape,size_x,size_y,size_z,pos_x,pos_y,pos_z,yaw_deg; metres; z of the
// ground = ground_z). Labels map to classes (Topiary-* -> topiary, Hedge-* -> hedge, Rose-* -> rose,
// Obstacle-Tree -> tree, Obstacle-Trunk -> trunk, Obstacle-Fence/Post -> fence, others -> obstacle).
// Objects starting less than 0.3 m up are grounded (their tops kept). Throws InputError naming the
// file and line.
Garden ImportGardenUiCsv(const std::string& path, double ground_z);

struct GeneratorParameters {
  std::uint64_t seed = 0;
  Eigen::Vector2d size = Eigen::Vector2d(16, 12);
  int topiary = 8;
  double topiary_box_share = 0.3;       // of the topiaries shaped as boxes (drawn per bush) ...
  double topiary_cylinder_share = 0.0;  // ... and as cylinders; the rest ellipsoids
  int roses = 4;
  int hedges = 2;
  int trees = 2;
  int obstacles = 2;
  int paths = 2;
  // Pairs of parallel hedges with a corridor between them the robot must drive through (its width
  // drawn from corridor_width; the hedges' ends are open).
  int corridors = 0;
  Eigen::Vector2d corridor_width = Eigen::Vector2d(1.0, 1.2);  // m, min and max
  bool fence = true;                                           // a low fence around the garden
  double robot_clearance = 0.9;  // m of free space kept between objects so the robot can pass
  double fence_clearance = 0.5;  // m kept between objects and the garden's edge
};
// A new garden from the parameters; the same seed gives the same garden. Objects do not overlap
// each other or the paths and keep robot_clearance between them.
Garden GenerateGarden(const GeneratorParameters& parameters);

struct OccupancyMap {
  cv::Mat occupied;          // CV_8U, 255 = occupied, row 0 = the map's top (largest y)
  double resolution = 0.05;  // m per cell
  Eigen::Vector2d origin;    // map coordinates of the bottom-left corner of the bottom-left cell
  // Cell (column, row) holding a map point, and the map point at a cell's centre.
  cv::Point Cell(const Eigen::Vector2d& point) const;
  Eigen::Vector2d CellCentre(const cv::Point& cell) const;
};
// How much of an object's footprint its part below `clearance` covers (a scale of its size): all of
// it for boxes and cylinders (upright prisms) and for ellipsoids reaching their widest below it,
// else the ellipsoid's cross-section at that height (a tree crown the robot passes under at its rim
// but not near the trunk). 0 when nothing of it is below.
double FootprintScaleBelow(const GardenObject& object, double clearance);
// Points along the boundary of an object's footprint scaled by `scale` (FootprintScaleBelow), at
// most `spacing` apart, corners of a box included: for exact distances to the footprint (a
// polygon's distance to it errs by at most half the spacing).
std::vector<Eigen::Vector2d> FootprintBoundary(const GardenObject& object, double scale, double spacing);
// The first object whose part below `clearance` covers `point` (what the robot can run into there;
// an ellipsoid crown by its cross-section at that height), or null.
const GardenObject* ObjectAt(const Garden& garden, const Eigen::Vector2d& point, double clearance);
// Footprints of every object's part below `clearance`, the robot's height (tree crowns higher than
// the robot are not obstacles to it, their trunks are; a crown lower than it is, by its
// cross-section at that height).
OccupancyMap MakeOccupancyMap(const Garden& garden, double resolution, double clearance);
// Writes <dir>/<name>.png and <dir>/<name>.yaml in ROS map_server format.
void WriteOccupancyMap(const OccupancyMap& map, const std::string& dir, const std::string& name);

// A point on a true surface of the garden, with its class and object id (kGroundObjectId: lawn).
struct SurfaceSample {
  Eigen::Vector3d position;
  ObjectClass object_class;
  int object = 0;
};
// Seeded samples of the garden's surfaces (as WriteGroundTruthPly writes them).
std::vector<SurfaceSample> SampleSurfaces(const Garden& garden, double growth, double points_per_m2);
// Samples the garden's surfaces (ground, paths, object meshes as grown under `growth`, shaped by the
// garden's appearance seed) into an ASCII PLY point cloud with per-point class and object id.
void WriteGroundTruthPly(const Garden& garden, double growth, double points_per_m2, const std::string& path);

}  // namespace trimbot::garden
