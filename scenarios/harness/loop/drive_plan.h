#pragma once
// A drive plan: open-loop commands for a headless drive of the robot (played by the drive-plan
// pilot: no robot software in the loop).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loop/setting.h"

namespace trimbot::scenarios {

struct DriveSegment {
  double duration = 0.0;                     // s
  double linear = 0.0;                       // m/s
  double angular = 0.0;                      // rad/s
  std::optional<std::array<double, 6>> arm;  // joint position target, rad
  bool cutter = false;
};

struct DrivePlan {
  std::string source;
  Setting setting;
  int save_every_frames = 10;
  std::vector<DriveSegment> segments;

  double duration() const;
  const DriveSegment& SegmentAt(double t) const;
  static DrivePlan Load(const std::string& path);
};

}  // namespace trimbot::scenarios
