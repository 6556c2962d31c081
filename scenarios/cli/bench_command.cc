#include "cli/bench_command.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "runner/closed_loop.h"
#include "runner/controllers.h"
#include "runner/drive_plan.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

sim::SimulatorConfig Config(const BenchOptions& options, bool cameras, double scale, int msaa = 4) {
  WorldSetup world;
  world.garden = options.garden;
  world.seed = 7;
  sim::SimulatorConfig config =
      MakeSimulatorConfig(options.paths, world, std::filesystem::temp_directory_path().string() + "/trimbot_bench_world");
  config.render_cameras = cameras;
  config.resolution_scale = scale;
  config.msaa_samples = msaa;
  return config;
}

nlohmann::json RenderCost(const BenchOptions& options, double scale, int msaa) {
  sim::Simulator simulator(Config(options, true, scale, msaa));
  simulator.CaptureRing(false);  // warm-up: shader compilation, texture upload
  auto start = Clock::now();
  for (int i = 0; i < options.frames; ++i) simulator.CaptureRing(false);
  const double ring_ms = 1000.0 * Seconds(start) / options.frames;
  start = Clock::now();
  for (int i = 0; i < options.frames; ++i) simulator.CaptureRing(true);
  const double ring_truth_ms = 1000.0 * Seconds(start) / options.frames;
  const auto& model = simulator.rig().camera(0).intrinsics;
  nlohmann::json out;
  out["width"] = static_cast<int>(std::lround(model.width * scale));
  out["height"] = static_cast<int>(std::lround(model.height * scale));
  out["ms_per_camera"] = ring_ms / simulator.rig().size();
  out["ms_per_ring"] = ring_ms;
  out["ms_per_camera_with_depth_and_labels"] = ring_truth_ms / simulator.rig().size();
  out["ms_per_ring_with_depth_and_labels"] = ring_truth_ms;
  out["msaa_samples"] = msaa;
  std::printf("  %4dx%-4d msaa %d  %7.1f ms/camera  %7.1f ms/ring  | with depth+labels %7.1f ms/camera %7.1f ms/ring\n",
              out["width"].get<int>(), out["height"].get<int>(), msaa, ring_ms / simulator.rig().size(), ring_ms,
              ring_truth_ms / simulator.rig().size(), ring_truth_ms);
  return out;
}

// Real-time factor of the loop driving an arc open-loop for `seconds` (no robot software).
double DriveRealTimeFactor(const BenchOptions& options, bool cameras, double scale, double seconds, double angular) {
  sim::Simulator simulator(Config(options, cameras, scale));
  DrivePlan plan;
  plan.segments.push_back({seconds, 0.25, angular, std::nullopt, false});
  DrivePlanPlayer player(plan, seconds);
  LoopOptions loop;
  loop.time_limit = seconds;
  const auto start = Clock::now();
  RunClosedLoop(simulator, player, {}, loop);
  return simulator.time() / Seconds(start);
}

}  // namespace

int RunBench(const BenchOptions& options) {
  nlohmann::json report;
  report["garden"] = options.garden;
  std::printf("rendering (%s, %d ring frames each, OSMesa/llvmpipe):\n", options.garden.c_str(), options.frames);
  report["render_full_resolution"] = RenderCost(options, 1.0, 4);
  report["render_half_resolution"] = RenderCost(options, 0.5, 4);
  report["render_full_resolution_no_msaa"] = RenderCost(options, 1.0, 0);
  report["render_half_resolution_no_msaa"] = RenderCost(options, 0.5, 0);

  {
    // Physics alone: 8000 steps of the loop without cameras.
    const double seconds = 8000 * sim::SimulatorConfig{}.timestep;
    const double rtf = DriveRealTimeFactor(options, false, 1.0, seconds, 0.2);
    const double per_second = rtf / sim::SimulatorConfig{}.timestep;
    report["physics_steps_per_second"] = per_second;
    report["physics_real_time_factor"] = rtf;
    std::printf("physics: %.0f steps/s (timestep %.4f s, real-time factor %.1f without cameras)\n", per_second,
                sim::SimulatorConfig{}.timestep, rtf);
  }
  const double rtf_full = DriveRealTimeFactor(options, true, 1.0, options.drive_seconds, 0.1);
  const double rtf_half = DriveRealTimeFactor(options, true, 0.5, options.drive_seconds, 0.1);
  report["drive_real_time_factor_full_resolution"] = rtf_full;
  report["drive_real_time_factor_half_resolution"] = rtf_half;
  report["drive_seconds"] = options.drive_seconds;
  std::printf("headless drive with the ring at 5 Hz: real-time factor %.2f (full resolution), %.2f (half)\n", rtf_full,
              rtf_half);
  if (!options.output_path.empty()) {
    WriteFileAtomically(options.output_path, report.dump(2) + "\n");
    std::printf("report: %s\n", options.output_path.c_str());
  }
  return 0;
}

}  // namespace trimbot::scenarios
