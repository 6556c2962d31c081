#pragma once
// A drive plan: open-loop commands for a headless drive of the robot (the main job until the
// closed-loop scenarios arrive).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "trimbot/garden/conditions.h"
#include "trimbot/sim/world_builder.h"

namespace trimbot::scenarios {

struct DriveSegment {
  double duration = 0.0;  // s
  double linear = 0.0;    // m/s
  double angular = 0.0;   // rad/s
  std::optional<std::array<double, 6>> arm;  // joint position target, rad
  bool cutter = false;
};

struct DrivePlan {
  std::string source;
  std::string garden;
  std::uint64_t seed = 0;
  sim::Pose2D start;
  garden::Conditions conditions;
  int save_every_frames = 10;
  std::vector<DriveSegment> segments;

  double duration() const;
  const DriveSegment& SegmentAt(double t) const;
  static DrivePlan Load(const std::string& path);
};

}  // namespace trimbot::scenarios
