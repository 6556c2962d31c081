#include "bench_command.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "trimbot/common/atomic_file.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

sim::SimulatorConfig Config(const BenchOptions& options, bool cameras, double scale, int msaa = 4) {
  sim::SimulatorConfig config = options.paths.SimulatorConfigFor(
      options.garden, std::filesystem::temp_directory_path().string() + "/trimbot_bench_world");
  config.seed = 7;
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

double DriveRealTimeFactor(const BenchOptions& options, bool cameras, double scale) {
  sim::Simulator simulator(Config(options, cameras, scale));
  sim::StepOutputs outputs;
  simulator.SetBaseCommand({0.25, 0.1});
  const auto start = Clock::now();
  while (simulator.time() < options.drive_seconds) {
    outputs.Clear();
    simulator.Step(&outputs);
  }
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
    sim::Simulator simulator(Config(options, false, 1.0));
    sim::StepOutputs outputs;
    simulator.SetBaseCommand({0.25, 0.2});
    const int steps = 8000;
    const auto start = Clock::now();
    for (int i = 0; i < steps; ++i) {
      outputs.Clear();
      simulator.Step(&outputs);
    }
    const double per_second = steps / Seconds(start);
    report["physics_steps_per_second"] = per_second;
    report["physics_real_time_factor"] = per_second * simulator.timestep();
    std::printf("physics: %.0f steps/s (timestep %.4f s, real-time factor %.1f without cameras)\n", per_second,
                simulator.timestep(), per_second * simulator.timestep());
  }
  const double rtf_full = DriveRealTimeFactor(options, true, 1.0);
  const double rtf_half = DriveRealTimeFactor(options, true, 0.5);
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
