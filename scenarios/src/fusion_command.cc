#include "fusion_command.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "drive_plan.h"
#include "project_paths.h"
#include "trial_result.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/perception/registration.h"
#include "trimbot/perception/stereo.h"
#include "trimbot/sim/simulator.h"
#include "trimbot/stack/wheel_odometry.h"

namespace trimbot::scenarios {
namespace {

using Clock = std::chrono::steady_clock;

double Mean(const std::vector<double>& v) { return ErrorStats::From(v).mean; }

struct Options {
  std::string plan;
  std::string out;
  double interval = 1.0;        // s between clouds
  int clouds = 20;
  double ground_keep = 0.02;    // fraction of ground points kept
  int stride = 4;               // pixel stride of the stereo clouds
};

int RunFusion(const Options& options, const ProjectPaths& paths) {
  const DrivePlan plan = DrivePlan::Load(options.plan);
  std::filesystem::create_directories(options.out);
  sim::SimulatorConfig config = paths.SimulatorConfigFor(plan.garden, options.out + "/world");
  config.seed = plan.seed;
  config.start = plan.start;
  config.conditions = plan.conditions;
  config.cameras_on_schedule = false;  // only the frames the fusion uses are rendered
  sim::Simulator simulator(config);
  stack::WheelOdometry odometry(simulator.robot().drive(), simulator.parameters().wheel_encoders.ticks_per_revolution);
  perception::StereoOptions stereo_options;
  stereo_options.stride = options.stride;  // every pixel would give ~500k points per ring
  const perception::RingStereo stereo(simulator.rig(), stereo_options);

  struct Keyframe {
    perception::PointCloud cloud;
    Eigen::Isometry3d odometry, truth;
  };
  std::optional<Keyframe> previous;
  std::vector<double> odom_translation, odom_rotation, dugma_translation, dugma_rotation, seconds;
  nlohmann::json pairs = nlohmann::json::array();
  std::cout << " pair  points(prev/cur)  odometry: trans (cm) rot (deg)   DUGMA: trans (cm) rot (deg)   time (s)\n";
  sim::StepOutputs outputs;
  double next_capture = 0.0;
  while (simulator.time() < plan.duration() && static_cast<int>(seconds.size()) < options.clouds) {
    const DriveSegment& segment = plan.SegmentAt(simulator.time());
    simulator.SetBaseCommand({segment.linear, segment.angular});
    outputs.Clear();
    simulator.Step(&outputs);
    for (const auto& ticks : outputs.wheel_ticks) odometry.Update(ticks);
    if (simulator.time() + 1e-9 < next_capture) continue;
    next_capture += options.interval;

    const sim::RingCapture capture = simulator.CaptureRing(false);
    perception::PointCloud cloud = stereo.RingCloud(capture.frame);
    if (const auto ground = perception::FitGroundPlane(cloud)) {
      cloud = perception::DownsampleGround(cloud, *ground, options.ground_keep, 0.05);
    }
    Keyframe current{std::move(cloud), stack::ToIsometry(odometry.pose()), simulator.ground_truth().T_map_base};
    if (previous && !current.cloud.empty() && !previous->cloud.empty()) {
      // Relative pose of the current base in the previous base frame.
      const Eigen::Isometry3d truth = previous->truth.inverse() * current.truth;
      const Eigen::Isometry3d guess = previous->odometry.inverse() * current.odometry;
      const auto start = Clock::now();
      const perception::RegistrationResult result = perception::Register(previous->cloud, current.cloud, guess);
      const double time = std::chrono::duration<double>(Clock::now() - start).count();
      odom_translation.push_back(perception::TranslationError(guess, truth) * 100.0);
      odom_rotation.push_back(perception::RotationErrorDegrees(guess, truth));
      dugma_translation.push_back(perception::TranslationError(result.transform, truth) * 100.0);
      dugma_rotation.push_back(perception::RotationErrorDegrees(result.transform, truth));
      seconds.push_back(time);
      std::cout << std::fixed << std::setw(5) << seconds.size() << std::setw(9) << previous->cloud.size() << "/"
                << std::left << std::setw(8) << current.cloud.size() << std::right << std::setprecision(2)
                << std::setw(19) << odom_translation.back() << std::setw(10) << odom_rotation.back() << std::setw(22)
                << dugma_translation.back() << std::setw(10) << dugma_rotation.back() << std::setprecision(3)
                << std::setw(11) << time << "\n";
      pairs.push_back({{"time", simulator.time()},
                       {"points", {previous->cloud.size(), current.cloud.size()}},
                       {"odometry_translation_cm", odom_translation.back()},
                       {"odometry_rotation_deg", odom_rotation.back()},
                       {"dugma_translation_cm", dugma_translation.back()},
                       {"dugma_rotation_deg", dugma_rotation.back()},
                       {"seconds", time}});
    }
    previous = std::move(current);
  }
  std::cout << std::fixed << std::setprecision(2) << "mean over " << seconds.size()
            << " pairs: odometry " << Mean(odom_translation) << " cm / " << Mean(odom_rotation)
            << " deg -> DUGMA " << Mean(dugma_translation) << " cm / " << Mean(dugma_rotation) << " deg, "
            << std::setprecision(3) << Mean(seconds) << " s per registration\n";
  const nlohmann::json summary = {{"plan", options.plan},
                                  {"interval_s", options.interval},
                                  {"pairs", pairs},
                                  {"mean",
                                   {{"odometry_translation_cm", Mean(odom_translation)},
                                    {"odometry_rotation_deg", Mean(odom_rotation)},
                                    {"dugma_translation_cm", Mean(dugma_translation)},
                                    {"dugma_rotation_deg", Mean(dugma_rotation)},
                                    {"seconds", Mean(seconds)}}}};
  WriteFileAtomically(options.out + "/fusion.json", summary.dump(2));
  return 0;
}

}  // namespace

void AddFusionCommand(CLI::App& app, const std::string& data_root, int& exit_code) {
  auto options = std::make_shared<Options>();
  auto* command = app.add_subcommand(
      "fusion", "register consecutive 360-degree stereo clouds of a drive (DUGMA from the odometry guess)");
  command->add_option("plan", options->plan, "drive plan (YAML)")->required();
  command->add_option("--out", options->out, "output folder")->required();
  command->add_option("--interval", options->interval, "seconds between clouds")->check(CLI::PositiveNumber);
  command->add_option("--clouds", options->clouds, "number of registrations")->check(CLI::PositiveNumber);
  command->add_option("--stride", options->stride, "pixel stride of the stereo clouds")->check(CLI::PositiveNumber);
  command->add_option("--ground-keep", options->ground_keep, "fraction of ground points kept")
      ->check(CLI::Range(0.0, 1.0));
  command->callback([options, &data_root, &exit_code]() { exit_code = RunFusion(*options, ProjectPaths{data_root}); });
}

}  // namespace trimbot::scenarios
