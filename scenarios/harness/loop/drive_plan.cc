#include "loop/drive_plan.h"

#include <cmath>

#include "trimbot/common/yaml_reader.h"

namespace trimbot::scenarios {

double DrivePlan::duration() const {
  double total = 0.0;
  for (const auto& segment : segments) total += segment.duration;
  return total;
}

const DriveSegment& DrivePlan::SegmentAt(double t) const {
  double end = 0.0;
  for (const auto& segment : segments) {
    end += segment.duration;
    if (t < end) return segment;
  }
  return segments.back();
}

DrivePlan DrivePlan::Load(const std::string& path) {
  const YamlMap root = YamlMap::LoadFile(path);
  DrivePlan plan;
  plan.source = path;
  plan.setting = Setting::Read(root, /*with_seed=*/true);
  plan.save_every_frames = root.Has("save_every_frames") ? root.Integer("save_every_frames", 1, 1000000) : 10;
  for (const YamlMap& item : root.MapList("segments")) {
    DriveSegment segment;
    segment.duration = item.Number("duration", 1e-3, 1e5, "s");
    segment.linear = item.Number("linear", -5.0, 5.0, "m/s");
    segment.angular = item.Number("angular", -10.0, 10.0, "rad/s");
    if (item.Has("arm")) {
      const auto q = item.Doubles("arm", 6);
      for (double angle : q) {
        if (std::abs(angle) > 4.0 * M_PI) item.Fail("arm", "joint angles must be in [-4 pi, 4 pi] rad");
      }
      segment.arm = std::array<double, 6>{q[0], q[1], q[2], q[3], q[4], q[5]};
    }
    segment.cutter = item.Bool("cutter", false);
    item.RejectUnknownKeys();
    plan.segments.push_back(segment);
  }
  if (plan.segments.empty()) root.Fail("segments", "needs at least one segment");
  root.RejectUnknownKeys();
  return plan;
}

}  // namespace trimbot::scenarios
