#pragma once
// Sensor messages: what the robot's drivers deliver to the stack. Plain data with timestamps in
// seconds of robot time; nothing here knows whether the source is the simulator or hardware.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace trimbot::messages {

// One camera image, row-major, top row first.
struct Image {
  double stamp = 0.0;     // s, mid-exposure
  int camera_index = -1;  // index into the camera rig calibration (cam0..cam9)
  int width = 0;
  int height = 0;
  std::string encoding = "rgb8";  // "rgb8" (3 bytes per pixel) or "mono8"
  std::vector<std::uint8_t> data;
};

// The ring's cameras are triggered together; one RingFrame holds one image per camera.
struct RingFrame {
  double stamp = 0.0;
  std::vector<Image> images;
};

// Specific force and angular rate in the IMU frame (imu_link), as a real IMU reports them:
// at rest, linear_acceleration is about (0, 0, +9.81).
struct ImuSample {
  double stamp = 0.0;
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  // m/s^2
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     // rad/s
};

// Cumulative encoder counts of the two drive wheels; forward rotation counts up.
struct WheelTicks {
  double stamp = 0.0;
  std::int64_t left = 0;
  std::int64_t right = 0;
};

// Positions and velocities of the arm's six joints, as the arm's firmware reports them.
struct ArmJointState {
  double stamp = 0.0;
  std::array<double, 6> position{};  // rad, arm_joint_1..6
  std::array<double, 6> velocity{};  // rad/s
};

// An absolute pose of base_link in the map frame from a localization source outside the stack's
// own components (e.g. a separate localization process, or the test fixture that simulates one). `stamp` is when the
// pose was true (the capture time of the images it came from); it arrives later, after the source's processing time.
struct PoseFix {
  double stamp = 0.0;
  double x = 0.0, y = 0.0, yaw = 0.0;                        // m, m, rad (map frame)
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // of (x, y, yaw)
};

}  // namespace trimbot::messages
