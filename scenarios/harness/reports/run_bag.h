#pragma once
// trials/NNN/run.bag: the trial as a ROS 1 bag, for the tools robotics engineers already use
// (Foxglove Studio, PlotJuggler, rqt_bag, `evo_traj bag`). Written with Debian's rosbag_storage
// library (no ROS installation), standard message types, REP-105 frames and SI units:
//   /tf_static    base_link -> imu_link, camN_optical_frame, arm_link_base; arm_link_6 ->
//                 arm_end_effector (the robot as simulated)
//   /tf           map -> odom (the EKF's correction of the wheel odometry), odom -> base_link
//                 (the wheel odometry), at pose_rate; the arm's joints (arm_link_base ->
//                 arm_link_1 -> ... -> arm_link_6) at each joint state
//   /costmap                    nav_msgs/OccupancyGrid, map: the navigator's obstacles (the prior
//                               map's and those perception added: 100), at costmap_rate
//   /ground_truth/pose          geometry_msgs/PoseStamped, map, at pose_rate
//   /ekf/pose                   geometry_msgs/PoseWithCovarianceStamped, map, at pose_rate
//   /wheel_odometry             nav_msgs/Odometry, odom -> base_link, at pose_rate
//   /imu                        sensor_msgs/Imu, imu_link, every sample
//   /joint_states               sensor_msgs/JointState, the arm's joints, every sample
//   /visual_localization/fix    geometry_msgs/PoseWithCovarianceStamped, map, each fix the EKF got
//   /cmd_vel                    geometry_msgs/Twist, the base's command, at most at pose_rate
//   /cam0/image/compressed      sensor_msgs/CompressedImage (JPEG), the ring's cam0 each frame the
//                               stack asked for, downscaled (optional: images = false)
//   /events                     std_msgs/String, the navigator's events ("goal_reached 3: ...")
// Stamps are the simulated time. The bag is written to run.bag.partial while the trial runs and
// renamed at Close(), so a run.bag is always complete.
#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "loop/closed_loop.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/robot/robot_description.h"

namespace rosbag {
class Bag;
}

namespace trimbot::scenarios {

struct RunBagOptions {
  double pose_rate = 50.0;  // Hz of the poses and /tf
  bool images = true;
  int image_downscale = 2;  // 752x480 -> 376x240
  int jpeg_quality = 80;
  // The robot as simulated (its URDF: the IMU's and the arm's frames) and its cameras in base_link
  // (REP-103 optical frames).
  const robot::RobotDescription* robot = nullptr;
  std::vector<Eigen::Isometry3d> T_base_cameras;
  // The navigator's costmap on `costmap_cells`' grid (RobotStack::CostmapLayers: 0 free, else an
  // obstacle; row 0 the top), sampled at costmap_rate; none when unset.
  std::function<cv::Mat()> costmap;
  garden::OccupancyMap costmap_cells;
  double costmap_rate = 1.0;  // Hz
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
  void RecordStatic(double t);
  void RecordCostmap(double t);

  std::string path_;
  RunBagOptions options_;
  std::unique_ptr<rosbag::Bag> bag_;
  double next_pose_ = 0.0, next_command_ = 0.0, next_costmap_ = 0.0;
  std::vector<std::string> arm_joints_;         // URDF names, arm_joint_1..6
  double last_event_ = -1.0, last_fix_ = -1.0;  // stamps written (the telemetry keeps the last update's)
  bool static_written_ = false;
  long messages_ = 0;
  double seconds_ = 0.0;
};

}  // namespace trimbot::scenarios
