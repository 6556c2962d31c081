#include "trimbot/garden/object_class.h"

#include <array>
#include <utility>

namespace trimbot::garden {
namespace {

constexpr std::array<std::pair<ObjectClass, const char*>, 10> kClassNames = {{
    {ObjectClass::kNone, "none"},
    {ObjectClass::kGround, "ground"},
    {ObjectClass::kTopiary, "topiary"},
    {ObjectClass::kRose, "rose"},
    {ObjectClass::kHedge, "hedge"},
    {ObjectClass::kTree, "tree"},
    {ObjectClass::kTrunk, "trunk"},
    {ObjectClass::kFence, "fence"},
    {ObjectClass::kObstacle, "obstacle"},
    {ObjectClass::kRobot, "robot"},
}};

constexpr std::array<std::pair<Surface, const char*>, 4> kSurfaceNames = {{
    {Surface::kGrass, "grass"},
    {Surface::kGravel, "gravel"},
    {Surface::kPavement, "pavement"},
    {Surface::kSoil, "soil"},
}};

template <typename Enum, size_t N>
std::string NameIn(const std::array<std::pair<Enum, const char*>, N>& table, Enum value) {
  for (const auto& [entry, name] : table) {
    if (entry == value) return name;
  }
  return "unknown";
}

template <typename Enum, size_t N>
std::optional<Enum> ValueIn(const std::array<std::pair<Enum, const char*>, N>& table, const std::string& name) {
  for (const auto& [entry, text] : table) {
    if (name == text) return entry;
  }
  return std::nullopt;
}

}  // namespace

std::string ToString(ObjectClass c) { return NameIn(kClassNames, c); }
std::optional<ObjectClass> ObjectClassFromString(const std::string& name) { return ValueIn(kClassNames, name); }
std::string ToString(Surface s) { return NameIn(kSurfaceNames, s); }
std::optional<Surface> SurfaceFromString(const std::string& name) { return ValueIn(kSurfaceNames, name); }

SurfaceProperties PropertiesOf(Surface s) {
  // Slip figures are typical of small wheeled robots: a few percent on grass, more on loose gravel.
  switch (s) {
    case Surface::kGrass:
      return {0.8, {0.03, 0.015, 2.0}};
    case Surface::kGravel:
      return {0.7, {0.05, 0.025, 1.0}};
    case Surface::kPavement:
      return {1.0, {0.005, 0.003, 5.0}};
    case Surface::kSoil:
      return {0.6, {0.06, 0.03, 1.0}};
  }
  return {};
}

}  // namespace trimbot::garden
