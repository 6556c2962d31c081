#pragma once
// Triangle meshes for garden objects, with texture coordinates in texture tiles. Hard objects
// (fences, posts, trunks, obstacles, path slabs) are plain boxes and cylinders. Foliage is a
// superellipsoid of the trimmed shape (ball, ellipsoid, rounded box, rounded cylinder) whose surface
// is displaced by seeded noise: leaf clumps always, and irregular outgrowth that increases with the
// season's growth. The trimmed shape is the target a trimming run cuts back to.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "trimbot/garden/garden.h"

namespace trimbot::garden {

struct Mesh {
  std::vector<Eigen::Vector3d> vertices;   // m, in the object frame (origin at the footprint centre, z up)
  std::vector<Eigen::Vector2d> texcoords;  // per vertex, in texture tiles
  std::vector<std::array<int, 3>> faces;   // counter-clockwise seen from outside

  double Area() const;
};

// How far the ground's meshes (lawn patches, path slabs) reach below their top. MuJoCo 2.2 draws
// the sun's shadow map from back faces, so a slab's own bottom is the occluder its top is tested
// against; that bottom must lie deeper than the depth a shadow-map texel spans (~1.6 cm texels
// over the Wageningen garden: 9 cm at a 10 deg sun), or the ground shadows itself in stripes
// ("acne") that stereo matched as floating surfaces and that changed the ground's look with the hour.
constexpr double kGroundSlabDepth = 0.15;  // m

// Box of the given full size, base on z = 0, textured `tile` metres per texture repeat.
Mesh BoxMesh(const Eigen::Vector3d& size, double tile);
// The lawn, in the map frame, as one mesh per ground variant (textures.h): square patches of
// `tile` metres covering [min, max] (grown to whole patches), each a slab (kGroundSlabDepth) whose top (z = 0)
// shows its variant once (texture coordinates 0..1). Variants are drawn per patch and whole
// columns and rows of patches are mirrored, all by `seed`; mirroring whole columns and rows keeps
// neighbours meeting on the same border texels, so the lawn has no seams and no period shorter
// than the garden.
std::vector<Mesh> LawnMeshes(const Eigen::Vector2d& min, const Eigen::Vector2d& max, double tile, std::uint64_t seed);
// Mesh of a garden object in its own frame; `growth` in 0..1 (see Conditions).
Mesh ObjectMesh(const GardenObject& object, std::uint64_t seed, double growth);
// Pose of the object frame in the map frame.
Eigen::Matrix4d ObjectPose(const GardenObject& object);

// Seeded smooth 3D value noise in -1..1 with unit feature size.
double ValueNoise(std::uint64_t seed, const Eigen::Vector3d& p);

}  // namespace trimbot::garden
