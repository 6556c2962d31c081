#pragma once
// Differential-drive kinematics of the base: body twist <-> wheel angular speeds.

namespace trimbot::robot {

struct WheelSpeeds {
  double left = 0.0;  // rad/s, positive drives forward
  double right = 0.0;
};

struct DiffDriveGeometry {
  double wheel_radius = 0.0;      // m
  double wheel_separation = 0.0;  // m, between the wheel contact points

  WheelSpeeds FromTwist(double linear, double angular) const {
    return {(linear - 0.5 * wheel_separation * angular) / wheel_radius,
            (linear + 0.5 * wheel_separation * angular) / wheel_radius};
  }
  double LinearFromWheels(const WheelSpeeds& w) const { return 0.5 * wheel_radius * (w.left + w.right); }
  double AngularFromWheels(const WheelSpeeds& w) const { return wheel_radius * (w.right - w.left) / wheel_separation; }
};

}  // namespace trimbot::robot
