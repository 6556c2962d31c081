#include "reports/run_log.h"

#include <cstdio>

#include "evaluation/tum_trajectory.h"
#include "loop/drive_recording.h"
#include "reports/output_files.h"
#include "trimbot/common/atomic_file.h"

namespace trimbot::scenarios {
namespace {

void SaveRing(const messages::RingFrame& frame, const sim::RingTruth& truth, const std::string& dir) {
  for (size_t i = 0; i < frame.images.size(); ++i) {
    const auto& image = frame.images[i];
    const std::string cam = dir + "/cam" + std::to_string(i);
    WritePng(cam + ".png", ImageView(image));
    if (i < truth.views.size()) {
      const auto& view = truth.views[i];
      WriteDepthPng(cam + "_depth.png", view.depth);
      WritePng(cam + "_class.png", view.object_class, false);
      WritePng(cam + "_object.png", view.object_id, false);
      WritePng(cam + "_class_preview.png", ColouriseClasses(view.object_class));
    }
  }
}

}  // namespace

void RunLog::Observe(const StepView& step) {
  LogSensors(step);
  LogTruth(step);
  if (step.sensors.ring && step.truth.ring) LogRing(step);
}

void RunLog::LogSensors(const StepView& step) {
  char line[256];
  for (const auto& s : step.sensors.imu) {
    std::snprintf(line, sizeof(line), "%.6f,%.6f,%.6f,%.6f,%.7f,%.7f,%.7f\n", s.stamp, s.linear_acceleration.x(),
                  s.linear_acceleration.y(), s.linear_acceleration.z(), s.angular_velocity.x(), s.angular_velocity.y(),
                  s.angular_velocity.z());
    imu_csv_ += line;
  }
  for (const auto& t : step.sensors.wheel_ticks) {
    std::snprintf(line, sizeof(line), "%.6f,%lld,%lld\n", t.stamp, static_cast<long long>(t.left),
                  static_cast<long long>(t.right));
    ticks_csv_ += line;
    if (step.telemetry != nullptr) odometry_tum_ += TumLine(t.stamp, ToIsometry(step.telemetry->odometry));
  }
}

void RunLog::LogTruth(const StepView& step) {
  const sim::GroundTruth& truth = step.truth;
  char line[256];
  base_tum_ += TumLine(truth.stamp, truth.T_map_base);
  std::snprintf(line, sizeof(line), "%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", truth.stamp, truth.arm_position[0],
                truth.arm_position[1], truth.arm_position[2], truth.arm_position[3], truth.arm_position[4],
                truth.arm_position[5]);
  arm_csv_ += line;
  if (!step.sensors.imu.empty()) {
    std::snprintf(line, sizeof(line), "%.6f,%.6f,%.6f,%.6f,%.7f,%.7f,%.7f\n", truth.stamp, truth.accelerometer_bias.x(),
                  truth.accelerometer_bias.y(), truth.accelerometer_bias.z(), truth.gyroscope_bias.x(),
                  truth.gyroscope_bias.y(), truth.gyroscope_bias.z());
    imu_bias_csv_ += line;
  }
  if (!truth.contacts.empty()) ++obstacle_contact_steps_;
}

void RunLog::LogRing(const StepView& step) {
  const messages::RingFrame& frame = *step.sensors.ring;
  const sim::RingTruth& truth = *step.truth.ring;
  char line[256];
  for (size_t i = 0; i < truth.T_map_camera.size(); ++i) {
    const Eigen::Isometry3d& pose = truth.T_map_camera[i];
    const Eigen::Quaterniond q(pose.rotation());
    std::snprintf(line, sizeof(line), "%.6f,%zu,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f\n", frame.stamp, i,
                  pose.translation().x(), pose.translation().y(), pose.translation().z(), q.x(), q.y(), q.z(), q.w());
    cameras_csv_ += line;
  }
  const bool save = frames_ % save_every_ == 0;
  if (save) {
    SaveRing(frame, truth, RecordedFrameFolder(out_, frames_));
    ++saved_frames_;
  }
  std::snprintf(line, sizeof(line), "%ld,%.6f,%d\n", frames_, frame.stamp, save ? 1 : 0);
  ring_csv_ += line;
  ++frames_;
}

void RunLog::Write() const {
  WriteFileAtomically(out_ + "/sensors/imu.csv", imu_csv_);
  WriteFileAtomically(out_ + "/sensors/wheel_ticks.csv", ticks_csv_);
  WriteFileAtomically(out_ + "/sensors/ring.csv", ring_csv_);
  WriteFileAtomically(out_ + "/ground_truth/base.tum", base_tum_);
  WriteFileAtomically(out_ + "/ground_truth/arm.csv", arm_csv_);
  WriteFileAtomically(out_ + "/ground_truth/cameras.csv", cameras_csv_);
  WriteFileAtomically(out_ + "/ground_truth/imu_bias.csv", imu_bias_csv_);
  WriteFileAtomically(out_ + "/estimates/wheel_odometry.tum", odometry_tum_);
}

}  // namespace trimbot::scenarios
