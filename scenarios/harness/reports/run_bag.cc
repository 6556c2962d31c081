#include "reports/run_bag.h"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "reports/output_files.h"
#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {
namespace {

// ROS time of a simulated stamp; rosbag refuses time zero.
ros::Time Stamp(double t) { return ros::Time(std::max(t, 1e-9)); }

Eigen::Isometry3d Planar(const Pose2& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(pose.x, pose.y, 0.0);
  T.linear() = Eigen::AngleAxisd(pose.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

geometry_msgs::Pose PoseMessage(const Eigen::Isometry3d& T) {
  geometry_msgs::Pose pose;
  pose.position.x = T.translation().x();
  pose.position.y = T.translation().y();
  pose.position.z = T.translation().z();
  const Eigen::Quaterniond q(T.rotation());
  pose.orientation.x = q.x();
  pose.orientation.y = q.y();
  pose.orientation.z = q.z();
  pose.orientation.w = q.w();
  return pose;
}

geometry_msgs::TransformStamped TransformMessage(double t, const std::string& parent, const std::string& child,
                                                 const Eigen::Isometry3d& T) {
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = Stamp(t);
  transform.header.frame_id = parent;
  transform.child_frame_id = child;
  const geometry_msgs::Pose pose = PoseMessage(T);
  transform.transform.translation.x = pose.position.x;
  transform.transform.translation.y = pose.position.y;
  transform.transform.translation.z = pose.position.z;
  transform.transform.rotation = pose.orientation;
  return transform;
}

// A planar pose's (x, y, yaw) covariance in the 6x6 (x, y, z, roll, pitch, yaw) of ROS.
boost::array<double, 36> Covariance6(const Eigen::Matrix3d& c) {
  boost::array<double, 36> out{};
  const int index[3] = {0, 1, 5};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out[static_cast<std::size_t>(6 * index[i] + index[j])] = c(i, j);
  }
  return out;
}

geometry_msgs::PoseWithCovarianceStamped PlanarPoseMessage(double t, const Pose2& pose, const Eigen::Matrix3d& c) {
  geometry_msgs::PoseWithCovarianceStamped message;
  message.header.stamp = Stamp(t);
  message.header.frame_id = "map";
  message.pose.pose = PoseMessage(Planar(pose));
  message.pose.covariance = Covariance6(c);
  return message;
}

}  // namespace

RunBag::RunBag(std::string path, RunBagOptions options)
    : path_(std::move(path)), options_(std::move(options)), bag_(std::make_unique<rosbag::Bag>()) {
  if (options_.robot != nullptr) arm_joints_ = options_.robot->ArmJointNames();
  try {
    bag_->open(path_ + ".partial", rosbag::bagmode::Write);
    // LZ4 chunks (Foxglove, PlotJuggler and rosbag read them): the zero covariances and fixed
    // frame names of 200 Hz IMU and 50 Hz poses shrink about fivefold.
    bag_->setCompression(rosbag::compression::LZ4);
  } catch (const std::exception& e) {
    throw InputError(path_ + ".partial", std::string("cannot be written: ") + e.what());
  }
}

RunBag::~RunBag() {
  // A bag never closed (the trial threw) stays .partial: incomplete, and named so. Closing it
  // may fail (a full disk); the trial's own error is the one to report.
  try {
    if (bag_) bag_->close();
  } catch (const std::exception&) {
  }
}

void RunBag::Observe(const StepView& step) {
  const auto begin = std::chrono::steady_clock::now();
  Record(step);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
}

void RunBag::Record(const StepView& step) {
  const double t = step.time;
  if (!static_written_) RecordStatic(t);
  RecordSensors(step);
  RecordStack(step);
  if (options_.costmap && t + 1e-9 >= next_costmap_) RecordCostmap(t);
  if (step.commands.base && t + 1e-9 >= next_command_) {
    geometry_msgs::Twist twist;
    twist.linear.x = step.commands.base->linear;
    twist.angular.z = step.commands.base->angular;
    bag_->write("/cmd_vel", Stamp(t), twist);
    ++messages_;
    next_command_ = NextSampleTime(t, options_.pose_rate);
  }
  if (t + 1e-9 < next_pose_) return;
  next_pose_ = NextSampleTime(t, options_.pose_rate);
  geometry_msgs::PoseStamped truth;
  truth.header.stamp = Stamp(t);
  truth.header.frame_id = "map";
  truth.pose = PoseMessage(step.truth.T_map_base);
  bag_->write("/ground_truth/pose", truth.header.stamp, truth);
  ++messages_;
  const stack::Telemetry* telemetry = step.telemetry;
  if (telemetry == nullptr) return;
  // REP-105: odom -> base_link is the wheel odometry (continuous, drifting); map -> odom is what
  // the EKF corrects it by, so that map -> odom -> base_link is the EKF's estimate.
  const Eigen::Isometry3d T_odom_base = Planar(telemetry->odometry);
  const Eigen::Isometry3d T_map_base = Planar(telemetry->estimate.pose);
  tf2_msgs::TFMessage tf;
  tf.transforms.push_back(TransformMessage(t, "map", "odom", T_map_base * T_odom_base.inverse()));
  tf.transforms.push_back(TransformMessage(t, "odom", "base_link", T_odom_base));
  bag_->write("/tf", Stamp(t), tf);
  bag_->write("/ekf/pose", Stamp(t), PlanarPoseMessage(t, telemetry->estimate.pose, telemetry->estimate.covariance));
  nav_msgs::Odometry odometry;
  odometry.header.stamp = Stamp(t);
  odometry.header.frame_id = "odom";
  odometry.child_frame_id = "base_link";
  odometry.pose.pose = PoseMessage(T_odom_base);
  bag_->write("/wheel_odometry", Stamp(t), odometry);
  messages_ += 3;
}

// The sensors' messages as the stack got them.
void RunBag::RecordSensors(const StepView& step) {
  for (const auto& sample : step.sensors.imu) {
    sensor_msgs::Imu imu;
    imu.header.stamp = Stamp(sample.stamp);
    imu.header.frame_id = "imu_link";
    imu.orientation_covariance[0] = -1.0;  // no orientation (REP-145)
    imu.angular_velocity.x = sample.angular_velocity.x();
    imu.angular_velocity.y = sample.angular_velocity.y();
    imu.angular_velocity.z = sample.angular_velocity.z();
    imu.linear_acceleration.x = sample.linear_acceleration.x();
    imu.linear_acceleration.y = sample.linear_acceleration.y();
    imu.linear_acceleration.z = sample.linear_acceleration.z();
    bag_->write("/imu", imu.header.stamp, imu);
    ++messages_;
  }
  for (const auto& joints : step.sensors.arm_joints) {
    sensor_msgs::JointState state;
    state.header.stamp = Stamp(joints.stamp);
    state.name = arm_joints_;
    state.position.assign(joints.position.begin(), joints.position.end());
    state.velocity.assign(joints.velocity.begin(), joints.velocity.end());
    bag_->write("/joint_states", state.header.stamp, state);
    ++messages_;
    if (options_.robot == nullptr) continue;
    tf2_msgs::TFMessage arm;
    for (std::size_t j = 0; j < arm_joints_.size() && j < joints.position.size(); ++j) {
      const auto joint = options_.robot->urdf().getJoint(arm_joints_[j]);
      arm.transforms.push_back(TransformMessage(joints.stamp, joint->parent_link_name, joint->child_link_name,
                                                robot::RobotDescription::JointTransform(*joint, joints.position[j])));
    }
    bag_->write("/tf", Stamp(joints.stamp), arm);
    ++messages_;
  }
  if (options_.images && step.sensors.ring) {
    for (const auto& image : step.sensors.ring->images) {
      if (image.camera_index != 0 || image.encoding != "rgb8") continue;
      cv::Mat bgr, small;
      cv::cvtColor(ImageView(image), bgr, cv::COLOR_RGB2BGR);
      const int scale = std::max(1, options_.image_downscale);
      cv::resize(bgr, small, cv::Size(image.width / scale, image.height / scale), 0, 0, cv::INTER_AREA);
      sensor_msgs::CompressedImage message;
      message.header.stamp = Stamp(image.stamp);
      message.header.frame_id = "cam0_optical_frame";
      message.format = "jpeg";
      cv::imencode(".jpg", small, message.data, {cv::IMWRITE_JPEG_QUALITY, options_.jpeg_quality});
      bag_->write("/cam0/image/compressed", message.header.stamp, message);
      ++messages_;
    }
  }
}

// What the stack reported: its events and the visual fixes its EKF got.
void RunBag::RecordStack(const StepView& step) {
  const stack::Telemetry* telemetry = step.telemetry;
  if (telemetry == nullptr) return;
  for (const auto& event : telemetry->events) {
    if (event.stamp <= last_event_) continue;  // the last update's events stay in the telemetry
    std_msgs::String text;
    text.data = std::string(stack::ToString(event.type)) + " " + std::to_string(event.goal) +
                (event.detail.empty() ? "" : ": " + event.detail);
    bag_->write("/events", Stamp(event.stamp), text);
    ++messages_;
  }
  if (!telemetry->events.empty()) last_event_ = std::max(last_event_, telemetry->events.back().stamp);
  for (const auto& applied : telemetry->visual_fixes) {
    if (applied.fix.stamp <= last_fix_) continue;
    const Pose2 pose{applied.fix.x, applied.fix.y, applied.fix.yaw};
    bag_->write("/visual_localization/fix", Stamp(applied.fix.stamp),
                PlanarPoseMessage(applied.fix.stamp, pose, applied.fix.covariance));
    ++messages_;
    last_fix_ = std::max(last_fix_, applied.fix.stamp);
  }
}

// The robot's fixed frames, once.
void RunBag::RecordStatic(double t) {
  tf2_msgs::TFMessage fixed;
  for (std::size_t k = 0; k < options_.T_base_cameras.size(); ++k) {
    fixed.transforms.push_back(
        TransformMessage(t, "base_link", "cam" + std::to_string(k) + "_optical_frame", options_.T_base_cameras[k]));
  }
  if (options_.robot != nullptr) {
    const robot::RobotDescription& robot = *options_.robot;
    fixed.transforms.push_back(TransformMessage(t, "base_link", "imu_link", robot.FramePose("imu_link")));
    if (!arm_joints_.empty()) {
      const auto first = robot.urdf().getJoint(arm_joints_.front());
      const auto last = robot.urdf().getJoint(arm_joints_.back());
      fixed.transforms.push_back(
          TransformMessage(t, "base_link", first->parent_link_name, robot.FramePose(first->parent_link_name)));
      fixed.transforms.push_back(TransformMessage(
          t, last->child_link_name, robot::RobotFrames::kEndEffector,
          robot.FramePose(last->child_link_name).inverse() * robot.FramePose(robot::RobotFrames::kEndEffector)));
    }
  }
  bag_->write("/tf_static", Stamp(t), fixed);
  ++messages_;
  static_written_ = true;
}

// The navigator's costmap as an occupancy grid (row 0 at the bottom, REP-103's y up).
void RunBag::RecordCostmap(double t) {
  next_costmap_ = NextSampleTime(t, options_.costmap_rate);
  const cv::Mat layers = options_.costmap();
  if (layers.empty()) return;
  nav_msgs::OccupancyGrid grid;
  grid.header.stamp = Stamp(t);
  grid.header.frame_id = "map";
  grid.info.map_load_time = Stamp(t);
  grid.info.resolution = static_cast<float>(options_.costmap_cells.resolution);
  grid.info.width = static_cast<std::uint32_t>(layers.cols);
  grid.info.height = static_cast<std::uint32_t>(layers.rows);
  grid.info.origin.position.x = options_.costmap_cells.origin.x();
  grid.info.origin.position.y = options_.costmap_cells.origin.y();
  grid.info.origin.orientation.w = 1.0;
  grid.data.resize(static_cast<std::size_t>(layers.rows) * static_cast<std::size_t>(layers.cols));
  for (int row = 0; row < layers.rows; ++row) {
    const std::uint8_t* cells = layers.ptr<std::uint8_t>(layers.rows - 1 - row);
    for (int col = 0; col < layers.cols; ++col)
      grid.data[static_cast<std::size_t>(row) * static_cast<std::size_t>(layers.cols) + static_cast<std::size_t>(col)] =
          cells[col] > 0 ? 100 : 0;
  }
  bag_->write("/costmap", grid.header.stamp, grid);
  ++messages_;
}

void RunBag::Close() {
  const auto begin = std::chrono::steady_clock::now();
  const std::unique_ptr<rosbag::Bag> bag = std::move(bag_);  // closed once, even if it throws
  bag->close();
  std::filesystem::rename(path_ + ".partial", path_);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
}

}  // namespace trimbot::scenarios
