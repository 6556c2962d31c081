#include "runners/drive.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>

#include "loop/closed_loop.h"
#include "loop/drive_plan.h"
#include "loop/pilots.h"
#include "reports/run_log.h"
#include "reports/run_timing.h"
#include "reports/trial_video.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/garden/garden.h"
#include "trimbot/sim/simulator.h"
#include "trimbot/stack/robot_stack.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;

using Clock = std::chrono::steady_clock;

sim::SimulatorConfig PlantFor(const DriveOptions& options, const DrivePlan& plan, Setting setting) {
  if (options.seed) setting.seed = *options.seed;
  sim::SimulatorConfig config =
      MakeSimulatorConfig(options.paths, setting, LoadGarden(setting, options.paths), options.output_dir + "/world");
  if (!options.calibration_path.empty()) config.robot.camchain = options.calibration_path;
  config.render_cameras = options.cameras;
  config.ground_truth_every_frames = plan.save_every_frames;
  config.resolution_scale = options.resolution_scale;
  config.msaa_samples = options.msaa_samples;
  return config;
}

// A progress line on stderr about once per simulated second.
class ProgressLine : public Observer {
 public:
  ProgressLine(double duration, const RunLog& log) : duration_(duration), log_(log), start_(Clock::now()) {}
  void Observe(const StepView& step) override {
    if (step.time < next_) return;
    next_ += 1.0;
    const double wall = std::chrono::duration<double>(Clock::now() - start_).count();
    const Eigen::Vector3d p = step.truth.T_map_base.translation();
    std::fprintf(stderr, "\r[drive] sim %6.1f / %.1f s  wall %6.1f s  frames %ld  x %.2f y %.2f", step.time, duration_,
                 wall, log_.frames(), p.x(), p.y());
  }

 private:
  double duration_;
  const RunLog& log_;
  Clock::time_point start_;
  double next_ = 0.0;
};

nlohmann::json Summary(const DriveOptions& options, const DrivePlan& plan, const sim::SimulatorConfig& config,
                       const sim::Simulator& simulator, const RunLog& log, const stack::Telemetry& telemetry) {
  const sim::GroundTruth truth = simulator.ground_truth();
  const Pose2& odometry = telemetry.odometry;
  const Eigen::Vector3d end = truth.T_map_base.translation();
  nlohmann::json summary;
  summary["plan"] = options.plan_path;
  summary["garden"] = config.garden.source;
  summary["seed"] = config.seed;
  summary["conditions"] = {{"time_of_day", plan.setting.conditions.time_of_day},
                           {"day_of_year", plan.setting.conditions.day_of_year},
                           {"shadows", plan.setting.conditions.shadows},
                           {"growth", plan.setting.conditions.growth}};
  summary["calibration"] = config.robot.camchain;
  summary["simulated_seconds"] = simulator.time();
  summary["physics_timestep"] = simulator.timestep();
  summary["ring_frames"] = log.frames();
  summary["ring_frames_saved"] = log.saved_frames();
  summary["resolution_scale"] = options.resolution_scale;
  summary["msaa_samples"] = options.msaa_samples;
  summary["path_end"] = {end.x(), end.y()};
  summary["wheel_odometry_end_error_m"] = std::hypot(odometry.x - end.x(), odometry.y - end.y());
  summary["obstacle_contact_steps"] = log.obstacle_contact_steps();
  return summary;
}

}  // namespace

int RunDrive(const DriveOptions& options) {
  // The inputs are read and checked before the output folder is touched.
  const DrivePlan plan = DrivePlan::Load(options.plan_path);
  const sim::SimulatorConfig config = PlantFor(options, plan, plan.setting);
  const stack::StackParameters parameters = stack::StackParameters::Load(options.paths.robot_files().stack_parameters);
  const std::string out = options.output_dir;
  fs::create_directories(out);
  const auto setup_start = Clock::now();
  sim::Simulator simulator(config);
  WriteFileAtomically(out + "/calibration/camchain.yaml", simulator.rig().ToKalibrYaml());
  // The plan beside the log: `trimbot map build` takes the garden and the stated start from it.
  std::ifstream plan_file(options.plan_path);
  WriteFileAtomically(out + "/plan.yaml", std::string(std::istreambuf_iterator<char>(plan_file), {}));

  // The stack listens (wheel odometry, EKF) from the plan's start; the plan drives.
  stack::RobotStack listener(options.paths.robot_files(), parameters, config.seed);
  listener.SetInitialPose(0.0, plan.setting.start);
  const double duration = std::min(plan.duration(), options.seconds.value_or(plan.duration()));
  DrivePlanPlayer player(plan, duration, &listener);
  RunLog log(out, plan.save_every_frames);
  ProgressLine progress(duration, log);
  std::vector<Observer*> observers{&log};
  if (!options.quiet) observers.push_back(&progress);
  std::optional<TrialVideo> video;  // the top view without a map: a drive has none
  if (options.video) observers.push_back(&video.emplace(out + "/drive.mp4", simulator, garden::OccupancyMap{}));
  LoopOptions loop;
  loop.time_limit = duration;

  const auto run_start = Clock::now();
  std::string failure;
  try {
    RunClosedLoop(simulator, player, observers, loop);
  } catch (const std::exception& e) {
    failure = e.what();
  }
  if (!options.quiet) std::fprintf(stderr, "\n");
  if (video) video->Close();  // also after a failed drive: what happened up to it
  const auto report_start = Clock::now();
  log.Write();
  nlohmann::json summary = Summary(options, plan, config, simulator, log, listener.telemetry());
  summary["status"] = failure.empty() ? "completed" : "failed";
  if (!failure.empty()) summary["error"] = failure;
  WriteFileAtomically(out + "/summary.json", summary.dump(2) + "\n");
  const auto seconds = [](Clock::time_point from) {
    return std::chrono::duration<double>(Clock::now() - from).count();
  };
  const double wall = seconds(setup_start);
  const sim::SimulatorTimings sim_timing = simulator.timings();
  const RunTiming timing =
      MakeRunTiming(wall, simulator.time(), sim_timing, &listener.telemetry().timings,
                    std::chrono::duration<double>(run_start - setup_start).count(), seconds(report_start));
  const double render_seconds = sim_timing.RenderSeconds();
  const double ms_per_frame = sim_timing.ring_frames > 0 ? 1000.0 * render_seconds / sim_timing.ring_frames : 0.0;
  WriteFileAtomically(out + "/timing.json", ToJson(timing).dump(2) + "\n");
  WriteRunTimingChart(out + "/timing.png", "where the drive's time went", timing);

  if (!options.quiet) {
    std::printf(
        "drive %s: %.1f s simulated in %.1f s (real-time factor %.2f), %ld ring frames (%.0f ms each), "
        "odometry end error %.3f m\noutputs in %s\n",
        failure.empty() ? "completed" : "FAILED", simulator.time(), wall, simulator.time() / wall, log.frames(),
        ms_per_frame, summary["wheel_odometry_end_error_m"].get<double>(), out.c_str());
    std::printf("%s", FormatRunTiming(timing).c_str());
  }
  if (!failure.empty()) {
    std::fprintf(stderr, "error: %s\n", failure.c_str());
    return 1;
  }
  return 0;
}

}  // namespace trimbot::scenarios
