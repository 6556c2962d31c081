// The stack's wheel odometry on its own (links only the stack: no simulator, no MuJoCo).
#include <gtest/gtest.h>

#include <cmath>

#include "trimbot/stack/wheel_odometry.h"

namespace trimbot::stack {
namespace {

TEST(WheelOdometry, IntegratesAQuarterCircle) {
  const robot::DiffDriveGeometry geometry{0.115, 0.46};
  const int ticks_per_revolution = 2048;
  WheelOdometry odometry(geometry, ticks_per_revolution);
  // Radius 1 m, 90 degrees: each wheel's arc length from the geometry.
  const double radius = 1.0, angle = M_PI / 2;
  const double left_arc = (radius - geometry.wheel_separation / 2) * angle;
  const double right_arc = (radius + geometry.wheel_separation / 2) * angle;
  const int steps = 500;
  for (int i = 0; i <= steps; ++i) {
    const double s = static_cast<double>(i) / steps;
    const auto ticks = [&](double arc) {
      return static_cast<std::int64_t>(std::floor(s * arc / geometry.wheel_radius * ticks_per_revolution / (2 * M_PI)));
    };
    odometry.Update({s * 10.0, ticks(left_arc), ticks(right_arc)});
  }
  // Quantization (1 tick = 0.35 mm) limits the accuracy.
  EXPECT_NEAR(odometry.pose().x, 1.0, 0.003);
  EXPECT_NEAR(odometry.pose().y, 1.0, 0.003);
  EXPECT_NEAR(odometry.pose().yaw, M_PI / 2, 0.003);
  EXPECT_NEAR(odometry.angular_velocity(), angle / 10.0, 0.01);
}

}  // namespace
}  // namespace trimbot::stack
