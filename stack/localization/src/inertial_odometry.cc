#include "trimbot/stack/inertial_odometry.h"

namespace trimbot::stack {

InertialOdometry::InertialOdometry(const EkfParameters& parameters, const robot::DiffDriveGeometry& geometry,
                                   int ticks_per_revolution, double stamp, const Pose2& start)
    : ekf_(parameters, geometry, ticks_per_revolution), odometry_(geometry, ticks_per_revolution), start_(start) {
  // The EKF's pose is not used, only its bias: any prior does.
  ekf_.Initialize(stamp, start, Eigen::Matrix3d::Identity());
}

void InertialOdometry::Add(const messages::ImuSample& imu) {
  ekf_.AddImu(imu);
  odometry_.AddYawRate(imu.stamp, imu.angular_velocity.z() - ekf_.Estimate().gyro_bias);
}

void InertialOdometry::Add(const messages::WheelTicks& ticks) {
  ekf_.AddWheelTicks(ticks);
  odometry_.AddWheelTicks(ticks);
}

Pose2 InertialOdometry::pose() const { return ToPose2(ToIsometry(start_) * ToIsometry(odometry_.pose())); }

}  // namespace trimbot::stack
