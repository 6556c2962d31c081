#include "drive_command.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "drive_plan.h"
#include "output_files.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/garden/garden.h"
#include "trimbot/sim/simulator.h"
#include "trimbot/stack/wheel_odometry.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string FrameDir(const std::string& out, long frame) {
  std::ostringstream name;
  name << out << "/frames/" << std::setw(6) << std::setfill('0') << frame;
  return name.str();
}

void SaveRing(const sim::RingCapture& capture, const std::string& dir) {
  for (size_t i = 0; i < capture.frame.images.size(); ++i) {
    const auto& image = capture.frame.images[i];
    const std::string cam = dir + "/cam" + std::to_string(i);
    const cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.data.data()));
    WritePng(cam + ".png", rgb);
    if (i < capture.ground_truth.size()) {
      const auto& truth = capture.ground_truth[i];
      WriteDepthPng(cam + "_depth.png", truth.depth);
      WritePng(cam + "_class.png", truth.object_class, false);
      WritePng(cam + "_object.png", truth.object_id, false);
      WritePng(cam + "_class_preview.png", ColouriseClasses(truth.object_class));
    }
  }
}

}  // namespace

int RunDrive(const DriveOptions& options) {
  const DrivePlan plan = DrivePlan::Load(options.plan_path);
  const std::string out = options.output_dir;
  fs::create_directories(out);

  sim::SimulatorConfig config = options.paths.SimulatorConfigFor(plan.garden, out + "/world");
  if (!options.calibration_path.empty()) config.calibration_path = options.calibration_path;
  config.seed = options.seed.value_or(plan.seed);
  config.start = plan.start;
  config.conditions = plan.conditions;
  config.render_cameras = options.cameras;
  config.ground_truth_every_frames = plan.save_every_frames;
  config.resolution_scale = options.resolution_scale;
  config.msaa_samples = options.msaa_samples;

  const auto setup_start = Clock::now();
  sim::Simulator simulator(config);
  const double setup_seconds = std::chrono::duration<double>(Clock::now() - setup_start).count();
  WriteFileAtomically(out + "/calibration/camchain.yaml", simulator.rig().ToKalibrYaml());

  stack::WheelOdometry odometry(simulator.robot().drive(), simulator.parameters().wheel_encoders.ticks_per_revolution);
  const double duration = std::min(plan.duration(), options.seconds.value_or(plan.duration()));

  std::string imu_csv = "t,ax,ay,az,gx,gy,gz\n";
  std::string ticks_csv = "t,left,right\n";
  std::string base_tum, odometry_tum, arm_csv = "t,q1,q2,q3,q4,q5,q6\n";
  std::string cameras_csv = "t,camera,x,y,z,qx,qy,qz,qw\n";
  std::string imu_bias_csv = "t,bax,bay,baz,bgx,bgy,bgz\n";
  const Eigen::Isometry3d T_map_odom = simulator.ground_truth().T_map_base;
  long frames = 0, saved_frames = 0, obstacle_contact_steps = 0;
  double render_seconds = 0.0;
  const auto run_start = Clock::now();
  double next_report = 0.0;

  auto write_logs = [&]() {
    WriteFileAtomically(out + "/sensors/imu.csv", imu_csv);
    WriteFileAtomically(out + "/sensors/wheel_ticks.csv", ticks_csv);
    WriteFileAtomically(out + "/ground_truth/base.tum", base_tum);
    WriteFileAtomically(out + "/ground_truth/arm.csv", arm_csv);
    WriteFileAtomically(out + "/ground_truth/cameras.csv", cameras_csv);
    WriteFileAtomically(out + "/ground_truth/imu_bias.csv", imu_bias_csv);
    WriteFileAtomically(out + "/estimates/wheel_odometry.tum", odometry_tum);
  };

  sim::StepOutputs outputs;
  std::string failure;
  try {
    while (simulator.time() < duration - 1e-9) {
      const DriveSegment& segment = plan.SegmentAt(simulator.time());
      simulator.SetBaseCommand({segment.linear, segment.angular});
      if (segment.arm) {
        messages::ArmCommand arm;
        arm.position = *segment.arm;
        simulator.SetArmCommand(arm);
      }
      simulator.SetCutterCommand({segment.cutter});

      outputs.Clear();
      const auto step_start = Clock::now();
      simulator.Step(&outputs);
      if (outputs.ring) render_seconds += std::chrono::duration<double>(Clock::now() - step_start).count();

      char line[256];
      for (const auto& s : outputs.imu) {
        std::snprintf(line, sizeof(line), "%.6f,%.6f,%.6f,%.6f,%.7f,%.7f,%.7f\n", s.stamp, s.linear_acceleration.x(),
                      s.linear_acceleration.y(), s.linear_acceleration.z(), s.angular_velocity.x(),
                      s.angular_velocity.y(), s.angular_velocity.z());
        imu_csv += line;
      }
      for (const auto& t : outputs.wheel_ticks) {
        std::snprintf(line, sizeof(line), "%.6f,%lld,%lld\n", t.stamp, static_cast<long long>(t.left),
                      static_cast<long long>(t.right));
        ticks_csv += line;
        odometry.Update(t);
        odometry_tum += TumLine(t.stamp, T_map_odom * stack::ToIsometry(odometry.pose()));
      }
      const sim::GroundTruth truth = simulator.ground_truth();
      base_tum += TumLine(truth.stamp, truth.T_map_base);
      std::snprintf(line, sizeof(line), "%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", truth.stamp, truth.arm_position[0],
                    truth.arm_position[1], truth.arm_position[2], truth.arm_position[3], truth.arm_position[4],
                    truth.arm_position[5]);
      arm_csv += line;
      if (!outputs.imu.empty()) {
        std::snprintf(line, sizeof(line), "%.6f,%.6f,%.6f,%.6f,%.7f,%.7f,%.7f\n", truth.stamp,
                      truth.accelerometer_bias.x(), truth.accelerometer_bias.y(), truth.accelerometer_bias.z(),
                      truth.gyroscope_bias.x(), truth.gyroscope_bias.y(), truth.gyroscope_bias.z());
        imu_bias_csv += line;
      }
      if (!simulator.ObstacleContacts().empty()) ++obstacle_contact_steps;

      if (outputs.ring) {
        for (size_t i = 0; i < outputs.ring->T_map_camera.size(); ++i) {
          const Eigen::Isometry3d& pose = outputs.ring->T_map_camera[i];
          const Eigen::Quaterniond q(pose.rotation());
          std::snprintf(line, sizeof(line), "%.6f,%zu,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f\n", outputs.ring->frame.stamp,
                        i, pose.translation().x(), pose.translation().y(), pose.translation().z(), q.x(), q.y(),
                        q.z(), q.w());
          cameras_csv += line;
        }
        if (frames % plan.save_every_frames == 0) {
          SaveRing(*outputs.ring, FrameDir(out, frames));
          ++saved_frames;
        }
        ++frames;
      }
      if (!options.quiet && simulator.time() >= next_report) {
        const double wall = std::chrono::duration<double>(Clock::now() - run_start).count();
        std::fprintf(stderr, "\r[drive] sim %6.1f / %.1f s  wall %6.1f s  frames %ld  x %.2f y %.2f", simulator.time(),
                     duration, wall, frames, truth.T_map_base.translation().x(), truth.T_map_base.translation().y());
        next_report += 1.0;
      }
    }
  } catch (const std::exception& e) {
    failure = e.what();
  }
  if (!options.quiet) std::fprintf(stderr, "\n");
  write_logs();

  const double wall = std::chrono::duration<double>(Clock::now() - run_start).count();
  const sim::GroundTruth final_truth = simulator.ground_truth();
  Eigen::Isometry3d T_odom_base = Eigen::Isometry3d::Identity();
  T_odom_base.translation() << odometry.pose().x, odometry.pose().y, 0.0;
  const Eigen::Vector3d odometry_end = (T_map_odom * T_odom_base).translation();
  const double odometry_error =
      (odometry_end.head<2>() - final_truth.T_map_base.translation().head<2>()).norm();

  nlohmann::json summary;
  summary["plan"] = options.plan_path;
  summary["garden"] = config.garden_path;
  summary["seed"] = config.seed;
  summary["conditions"] = {{"time_of_day", plan.conditions.time_of_day},
                           {"day_of_year", plan.conditions.day_of_year},
                           {"shadows", plan.conditions.shadows},
                           {"growth", plan.conditions.growth}};
  summary["calibration"] = config.calibration_path;
  summary["simulated_seconds"] = simulator.time();
  summary["wall_seconds"] = wall;
  summary["setup_seconds"] = setup_seconds;
  summary["real_time_factor"] = simulator.time() / wall;
  summary["physics_timestep"] = simulator.timestep();
  summary["ring_frames"] = frames;
  summary["ring_frames_saved"] = saved_frames;
  summary["resolution_scale"] = options.resolution_scale;
  summary["msaa_samples"] = options.msaa_samples;
  summary["ms_per_ring_frame"] = frames > 0 ? 1000.0 * render_seconds / frames : 0.0;
  summary["path_end"] = {final_truth.T_map_base.translation().x(), final_truth.T_map_base.translation().y()};
  summary["wheel_odometry_end_error_m"] = odometry_error;
  summary["obstacle_contact_steps"] = obstacle_contact_steps;
  summary["status"] = failure.empty() ? "completed" : "failed";
  if (!failure.empty()) summary["error"] = failure;
  WriteFileAtomically(out + "/summary.json", summary.dump(2) + "\n");

  if (!options.quiet) {
    std::printf("drive %s: %.1f s simulated in %.1f s (real-time factor %.2f), %ld ring frames (%.0f ms each), "
                "odometry end error %.3f m\noutputs in %s\n",
                failure.empty() ? "completed" : "FAILED", simulator.time(), wall, simulator.time() / wall, frames,
                frames > 0 ? 1000.0 * render_seconds / frames : 0.0, odometry_error, out.c_str());
  }
  if (!failure.empty()) {
    std::fprintf(stderr, "error: %s\n", failure.c_str());
    return 1;
  }
  return 0;
}

}  // namespace trimbot::scenarios
