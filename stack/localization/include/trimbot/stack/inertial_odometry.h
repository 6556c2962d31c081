#pragma once
// Wheel-inertial dead reckoning for a mapping drive, before any map exists: the wheels' distance
// along the gyro's heading (GyroOdometry), with the gyro's bias estimated by the EKF running on
// wheels and IMU alone (at standstill the wheels say the yaw rate is zero, so the bias shows). The
// same pairing RobotStack uses for the bush servo. Its pose is in the frame of the believed start.
#include "trimbot/common/pose2.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/robot/diff_drive.h"
#include "trimbot/stack/ekf.h"
#include "trimbot/stack/wheel_odometry.h"

namespace trimbot::stack {

class InertialOdometry {
 public:
  InertialOdometry(const EkfParameters& parameters, const robot::DiffDriveGeometry& geometry, int ticks_per_revolution,
                   double stamp, const Pose2& start);
  void Add(const messages::ImuSample& imu);
  void Add(const messages::WheelTicks& ticks);
  // start * (the motion since the start).
  Pose2 pose() const;

 private:
  Ekf ekf_;
  GyroOdometry odometry_;
  Pose2 start_;
};

}  // namespace trimbot::stack
