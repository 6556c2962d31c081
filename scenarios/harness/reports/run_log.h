#pragma once
// The record of a drive, as an observer of the loop: the sensor stream the stack saw
// (sensors/imu.csv, sensors/wheel_ticks.csv), the ground truth (ground_truth/base.tum at every
// step, arm.csv, cameras.csv per ring frame, imu_bias.csv), the stack's wheel odometry
// (estimates/wheel_odometry.tum) and every n-th ring frame with the renderer's depth and labels
// (frames/NNNNNN/). Write() saves the logs atomically (also after a failed run).
#include <string>

#include "loop/closed_loop.h"

namespace trimbot::scenarios {

class RunLog : public Observer {
 public:
  RunLog(std::string out_dir, int save_every_frames) : out_(std::move(out_dir)), save_every_(save_every_frames) {}

  void Observe(const StepView& step) override;
  void Write() const;

  long frames() const { return frames_; }
  long saved_frames() const { return saved_frames_; }
  long obstacle_contact_steps() const { return obstacle_contact_steps_; }

 private:
  void LogSensors(const StepView& step);
  void LogTruth(const StepView& step);
  void LogRing(const StepView& step);

  std::string out_;
  int save_every_;
  std::string imu_csv_ = "t,ax,ay,az,gx,gy,gz\n";
  std::string ticks_csv_ = "t,left,right\n";
  std::string ring_csv_ = "frame,t,saved\n";  // every ring frame's stamp, and whether frames/ holds it
  std::string base_tum_, odometry_tum_;
  std::string arm_csv_ = "t,q1,q2,q3,q4,q5,q6\n";
  std::string cameras_csv_ = "t,camera,x,y,z,qx,qy,qz,qw\n";
  std::string imu_bias_csv_ = "t,bax,bay,baz,bgx,bgy,bgz\n";
  long frames_ = 0, saved_frames_ = 0, obstacle_contact_steps_ = 0;
};

}  // namespace trimbot::scenarios
