#pragma once
// Procedural, seeded textures for garden surfaces, made at scene-build time and saved as PNG so
// MuJoCo can load them. They carry detail at the scale the ring cameras resolve (a few mm at 1-3 m)
// so stereo matching and feature detection have real structure to work with.
#include <opencv2/core.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "trimbot/garden/object_class.h"

namespace trimbot::garden {

enum class Material { kGrass, kGravel, kPavement, kSoil, kFoliage, kRoseFoliage, kTreeFoliage, kBark, kWood, kStone };

std::string ToString(Material m);
Material GroundMaterial(Surface s);
Material MaterialOf(ObjectClass c);
// Metres one texture tile covers on a surface.
double TileSize(Material m);

// The lawn is not one tile repeated: it is laid in patches (twice the tile: sim/world_builder),
// each showing one of kGroundVariants variants of its surface's tile chosen by the garden's seed
// (garden/object_mesh.h LawnMeshes); paths still repeat the base tile. The variants share a border band with the
// base tile (the same texels) and differ inside, so any arrangement of them is seamless.
constexpr int kGroundVariants = 4;
bool IsGround(Material m);

// Changes whenever a generator's output changes (caches of generated textures are keyed by it).
constexpr int kTextureGeneratorVersion = 3;

// Square BGR 8-bit image, the same for the same seed (for a ground material: the base tile).
cv::Mat MakeTexture(Material material, std::uint64_t seed, int size_px);
// The kGroundVariants variants of a ground material's tile (the base tile made once for all).
std::vector<cv::Mat> MakeGroundVariants(Material material, std::uint64_t seed, int size_px);

}  // namespace trimbot::garden
