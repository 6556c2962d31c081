#pragma once
// Procedural, seeded textures for garden surfaces, made at scene-build time and saved as PNG so
// MuJoCo can load them. They carry detail at the scale the ring cameras resolve (a few mm at 1-3 m)
// so stereo matching and feature detection have real structure to work with.
#include <opencv2/core.hpp>

#include <cstdint>
#include <map>
#include <string>

#include "trimbot/garden/object_class.h"

namespace trimbot::garden {

enum class Material { kGrass, kGravel, kPavement, kSoil, kFoliage, kRoseFoliage, kTreeFoliage, kBark, kWood, kStone };

std::string ToString(Material m);
Material GroundMaterial(Surface s);
Material MaterialOf(ObjectClass c);
// Metres one texture tile covers on a surface.
double TileSize(Material m);

// Square BGR 8-bit image, the same for the same seed.
cv::Mat MakeTexture(Material material, std::uint64_t seed, int size_px);

}  // namespace trimbot::garden
