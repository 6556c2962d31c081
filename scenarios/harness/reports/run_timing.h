#pragma once
// Where a run's wall-clock time went, stage by stage: the simulator's (physics, drawing the
// camera images, reading them back, distortion, exposure and noise, ground-truth images), the
// stack's (EKF, the visual localization's stages, stereo, planning, control) and the runner's
// (setup, report writing, the rest: loop, evaluation, logging). Written to timing.json beside
// summary.json (wall-clock figures differ run to run; summary.json stays reproducible), printed
// at the end of a run and drawn as a bar chart.
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "trimbot/sim/simulator.h"
#include "trimbot/stack/robot_stack.h"

namespace trimbot::scenarios {

struct StageTime {
  std::string name;   // e.g. "render_draw"
  std::string group;  // simulator | stack | runner
  double seconds = 0.0;
  long count = 0;   // what the time is spread over (0: nothing counted) ...
  std::string per;  // ... e.g. "camera image", "ring frame", "physics step"
};

struct RunTiming {
  double wall_seconds = 0.0;
  double simulated_seconds = 0.0;
  std::vector<StageTime> stages;  // the last is "other": wall time no stage accounts for
};

// `stack` may be null (no robot software ran). `setup_seconds` and `report_seconds` are the
// runner's own (world and stack construction; writing the outputs).
RunTiming MakeRunTiming(double wall_seconds, double simulated_seconds, const sim::SimulatorTimings& simulator,
                        const stack::StackTimings* stack, double setup_seconds, double report_seconds);

// {"wall_seconds", "simulated_seconds", "real_time_factor", "stages": [{"name", "group",
// "seconds", "share", "count", "per", "ms_per"}...]}.
nlohmann::json ToJson(const RunTiming& timing);
// Back from ToJson's output; throws std::runtime_error if it is not one.
RunTiming RunTimingFromJson(const nlohmann::json& json);
// The stages of several runs added (a batch: wall and simulated seconds add too).
RunTiming Sum(const std::vector<RunTiming>& runs);

// A table for the terminal: stage, seconds, share, ms per counted item.
std::string FormatRunTiming(const RunTiming& timing);
// Horizontal bars per stage, coloured by group. Writes the PNG atomically.
void WriteRunTimingChart(const std::string& path, const std::string& title, const RunTiming& timing);

}  // namespace trimbot::scenarios
