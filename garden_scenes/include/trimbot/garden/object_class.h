#pragma once
// Semantic classes of what is in a garden. The label images, the occupancy map and the evaluation
// all use these numbers; 0 means "nothing" (sky / no geometry).
#include <cstdint>
#include <optional>
#include <string>

namespace trimbot::garden {

enum class ObjectClass : std::uint8_t {
  kNone = 0,
  kGround = 1,
  kTopiary = 2,
  kRose = 3,
  kHedge = 4,
  kTree = 5,
  kTrunk = 6,
  kFence = 7,
  kObstacle = 8,
  kRobot = 9,
};

std::string ToString(ObjectClass c);
std::optional<ObjectClass> ObjectClassFromString(const std::string& name);

// Ground surfaces differ in look, friction and wheel slip.
enum class Surface { kGrass, kGravel, kPavement, kSoil };  // soil: bark-mulched beds
std::string ToString(Surface s);
std::optional<Surface> SurfaceFromString(const std::string& name);

// How much a driven wheel slips on a surface: the wheel turns (1 + slip) times as far as the base
// travels; slip is a first-order Gauss-Markov process with this mean, spread and correlation time.
struct SlipModel {
  double mean = 0.0;
  double sigma = 0.0;
  double correlation_time = 1.0;  // s
};

struct SurfaceProperties {
  double friction = 1.0;  // sliding friction coefficient
  SlipModel slip;
};

SurfaceProperties PropertiesOf(Surface s);

}  // namespace trimbot::garden

namespace trimbot::garden {

// Object ids in the per-pixel object image: garden objects keep the id of their garden file
// (1..kMaxGardenObjectId); the ground and the robot have ids of their own; 0 is "nothing".
constexpr std::uint16_t kMaxGardenObjectId = 60000;
constexpr std::uint16_t kGroundObjectId = 60001;
constexpr std::uint16_t kRobotObjectId = 60002;

}  // namespace trimbot::garden
