#pragma once
// trials/NNN/run.bag: the trial as a ROS 1 bag, for the tools robotics engineers already use
// (Foxglove Studio, PlotJuggler, rqt_bag, `evo_traj bag`). Written with Debian's rosbag_storage
// library (no ROS installation), standard message types, REP-105 frames and SI units:
//   /tf_static    base_link -> imu_link, camN_optical_frame (the robot as simulated)
//   /tf           map -> odom (the EKF's correction of the wheel odometry), odom -> base_link
//                 (the wheel odometry), at pose_rate
//   /ground_truth/pose          geometry_msgs/PoseStamped, map, at pose_rate
//   /ekf/pose                   geometry_msgs/PoseWithCovarianceStamped, map, at pose_rate
//   /wheel_odometry             nav_msgs/Odometry, odom -> base_link, at pose_rate
//   /imu                        sensor_msgs/Imu, imu_link, every sample
//   /joint_states               sensor_msgs/JointState, the arm's joints, every sample
//   /visual_localization/fix    geometry_msgs/PoseWithCovarianceStamped, map, each fix the EKF got
//   /cmd_vel                    geometry_msgs/Twist, each base command
//   /cam0/image/compressed      sensor_msgs/CompressedImage (JPEG), the ring's cam0 each frame the
//                               stack asked for, downscaled (optional: images = false)
//   /events                     std_msgs/String, the navigator's events ("goal_reached 3: ...")
// Stamps are the simulated time. The bag is written to run.bag.partial while the trial runs and
// renamed at Close(), so a run.bag is always complete.
#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "loop/closed_loop.h"

namespace rosbag {
class Bag;
}

namespace trimbot::scenarios {

struct RunBagOptions {
  double pose_rate = 50.0;  // Hz of the poses and /tf
  bool images = true;
  int image_downscale = 2;  // 752x480 -> 376x240
  int jpeg_quality = 80;
  // The robot's fixed frames in base_link (REP-103 optical frames for the cameras).
  Eigen::Isometry3d T_base_imu = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Isometry3d> T_base_cameras;
  std::vector<std::string> arm_joint_names;
};

class RunBag : public Observer {
 public:
  // Throws InputError naming the file when it cannot be opened for writing.
  RunBag(std::string path, RunBagOptions options);
  ~RunBag() override;
  RunBag(const RunBag&) = delete;
  RunBag& operator=(const RunBag&) = delete;

  void Observe(const StepView& step) override;
  // Closes the bag and moves it to its name.
  void Close();

  long messages() const { return messages_; }
  double seconds() const { return seconds_; }  // wall clock spent writing (for the timing report)

 private:
  void Record(const StepView& step);
  void RecordSensors(const StepView& step);
  void RecordStack(const StepView& step);

  std::string path_;
  RunBagOptions options_;
  std::unique_ptr<rosbag::Bag> bag_;
  double next_pose_ = 0.0, next_command_ = 0.0;
  double last_event_ = -1.0, last_fix_ = -1.0;  // stamps written (the telemetry keeps the last update's)
  bool static_written_ = false;
  long messages_ = 0;
  double seconds_ = 0.0;
};

}  // namespace trimbot::scenarios
