#include "runners/bench.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "loop/closed_loop.h"
#include "loop/drive_plan.h"
#include "loop/pilots.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

sim::SimulatorConfig Config(const BenchOptions& options, bool cameras, double scale, int msaa = 4, bool shadows = true,
                            bool culling = true) {
  Setting setting;
  setting.garden = options.garden;
  setting.seed = 7;
  setting.conditions.shadows = shadows;
  sim::SimulatorConfig config =
      MakeSimulatorConfig(options.paths, setting, LoadGarden(setting, options.paths),
                          std::filesystem::temp_directory_path().string() + "/trimbot_bench_world");
  config.render_cameras = cameras;
  config.resolution_scale = scale;
  config.msaa_samples = msaa;
  config.frustum_culling = culling;
  return config;
}

// One way of rendering the ring: which cameras, resolution, anti-aliasing, shadows, and whether
// two renderers (two OpenGL contexts, each on its own thread) share the cameras.
struct RenderVariant {
  std::string name;
  double scale = 1.0;
  int msaa = 4;
  bool shadows = true;
  bool left_only = false;  // the left camera of each pair (what localization asks for)
  bool two_threads = false;
  bool culling = true;  // each camera draws only the geoms that can show in it
};

messages::RingRequest RequestFor(const sim::Simulator& simulator, const RenderVariant& v) {
  messages::RingRequest request = simulator.WholeRing();
  if (v.left_only) {
    request.cameras.clear();
    for (const auto& pair : simulator.rig().StereoPairs()) request.cameras.push_back(pair.left);
    std::sort(request.cameras.begin(), request.cameras.end());
  }
  return request;
}

// Milliseconds per ring frame by stage (differences of the simulator's stage clocks).
nlohmann::json StageMs(const sim::SimulatorTimings& before, const sim::SimulatorTimings& after, int frames) {
  const auto ms = [&](double a, double b) { return 1000.0 * (b - a) / frames; };
  return {{"draw", ms(before.render_draw, after.render_draw)},
          {"readback", ms(before.render_readback, after.render_readback)},
          {"distortion", ms(before.distortion, after.distortion)},
          {"exposure_noise", ms(before.exposure_noise, after.exposure_noise)}};
}

nlohmann::json RenderCost(const BenchOptions& options, const RenderVariant& v) {
  const int renderers = v.two_threads ? 2 : 1;
  std::vector<std::unique_ptr<sim::Simulator>> simulators;
  std::vector<messages::RingRequest> requests;
  for (int r = 0; r < renderers; ++r) {
    simulators.push_back(
        std::make_unique<sim::Simulator>(Config(options, true, v.scale, v.msaa, v.shadows, v.culling)));
    messages::RingRequest request = RequestFor(*simulators.back(), v);
    if (v.two_threads) {  // each renderer takes every other camera
      std::vector<int> mine;
      for (std::size_t i = static_cast<std::size_t>(r); i < request.cameras.size(); i += 2)
        mine.push_back(request.cameras[i]);
      request.cameras = mine;
    }
    requests.push_back(request);
  }
  // Each renderer's OpenGL context is used on one thread only: warm-up (shader compilation,
  // texture upload) and frames; the clock starts when every renderer is warm.
  std::mutex mutex;
  std::condition_variable all_warm;
  int warm = 0;
  sim::SimulatorTimings before;
  Clock::time_point start;
  const auto render = [&](std::size_t r) {
    simulators[r]->CaptureRing(requests[r], false);
    {
      std::unique_lock<std::mutex> lock(mutex);
      if (++warm == renderers) {
        before = simulators[0]->timings();
        start = Clock::now();
        all_warm.notify_all();
      }
      all_warm.wait(lock, [&] { return warm == renderers; });
    }
    for (int i = 0; i < options.frames; ++i) simulators[r]->CaptureRing(requests[r], false);
  };
  std::vector<std::thread> threads;
  for (int r = 0; r < renderers; ++r) threads.emplace_back(render, static_cast<std::size_t>(r));
  for (auto& thread : threads) thread.join();
  const double ring_ms = 1000.0 * Seconds(start) / options.frames;
  std::size_t cameras = 0;
  for (const auto& request : requests) cameras += request.cameras.size();
  const auto& model = simulators[0]->rig().camera(0).intrinsics;
  nlohmann::json out = {{"variant", v.name},
                        {"width", static_cast<int>(std::lround(model.width * v.scale))},
                        {"height", static_cast<int>(std::lround(model.height * v.scale))},
                        {"cameras", cameras},
                        {"msaa_samples", v.msaa},
                        {"shadows", v.shadows},
                        {"frustum_culling", v.culling},
                        {"renderers", renderers},
                        {"ms_per_ring", ring_ms},
                        {"ms_per_camera", ring_ms / static_cast<double>(cameras)}};
  if (!v.two_threads) {
    const sim::SimulatorTimings after = simulators[0]->timings();
    out["stages_ms_per_ring"] = StageMs(before, after, options.frames);
    const long drawn = after.geoms_drawn - before.geoms_drawn, culled = after.geoms_culled - before.geoms_culled;
    out["geoms_drawn_fraction"] =
        drawn + culled > 0 ? static_cast<double>(drawn) / static_cast<double>(drawn + culled) : 1.0;
  }
  std::printf("  %-34s %2zu x %4dx%-4d  %7.1f ms/ring  %6.1f ms/camera", v.name.c_str(), cameras,
              out["width"].get<int>(), out["height"].get<int>(), ring_ms, ring_ms / static_cast<double>(cameras));
  if (!v.two_threads) {
    const auto& st = out["stages_ms_per_ring"];
    std::printf("  (draw %.1f, readback %.1f, distortion %.1f, exposure+noise %.1f; %.0f %% of the geoms drawn)",
                st["draw"].get<double>(), st["readback"].get<double>(), st["distortion"].get<double>(),
                st["exposure_noise"].get<double>(), 100.0 * out["geoms_drawn_fraction"].get<double>());
  }
  std::printf("\n");
  return out;
}

nlohmann::json GroundTruthCost(const BenchOptions& options) {
  sim::Simulator simulator(Config(options, true, 1.0));
  simulator.CaptureRing(true);
  const auto start = Clock::now();
  for (int i = 0; i < options.frames; ++i) simulator.CaptureRing(true);
  const double ms = 1000.0 * Seconds(start) / options.frames;
  std::printf("  full ring with depth and labels (ground truth): %.1f ms/ring\n", ms);
  return {{"ms_per_ring", ms}};
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
  std::printf("rendering (%s, %d ring frames each, OSMesa/llvmpipe, %u hardware threads):\n", options.garden.c_str(),
              options.frames, std::thread::hardware_concurrency());
  const std::vector<RenderVariant> variants = {
      {"full ring, msaa 4, shadows", 1.0, 4, true, false, false},
      {"full ring, msaa 4, shadows, no culling", 1.0, 4, true, false, false, false},
      {"full ring, msaa 0, shadows", 1.0, 0, true, false, false},
      {"full ring, msaa 4, no shadows", 1.0, 4, false, false, false},
      {"full ring, msaa 0, no shadows", 1.0, 0, false, false, false},
      {"full ring, msaa 4, two renderers", 1.0, 4, true, false, true},
      {"half resolution, msaa 4", 0.5, 4, true, false, false},
      {"half resolution, msaa 0", 0.5, 0, true, false, false},
      {"localization: 5 left, half, msaa 4", 0.5, 4, true, true, false},
      {"localization: 5 left, half, msaa 0", 0.5, 0, true, true, false},
  };
  nlohmann::json render = nlohmann::json::array();
  for (const auto& variant : variants) render.push_back(RenderCost(options, variant));
  report["render"] = render;
  report["render_full_ring_with_ground_truth"] = GroundTruthCost(options);

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
