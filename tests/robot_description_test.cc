// The robot description: URDF-derived geometry, the camera ring calibration (nominal and real)
// and their agreement.
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include <cmath>
#include <random>

#include "test_support.h"
#include "trimbot/common/input_error.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/robot/robot_parameters.h"

namespace trimbot {
namespace {

using robot::CameraRig;
using robot::RobotDescription;
using robot::RobotFrames;
using testing::SourcePath;

RobotDescription LoadRobot() { return RobotDescription::Load(SourcePath("robot/urdf/trimbot.urdf")); }

CameraRig LoadRig(const RobotDescription& robot, const std::string& file) {
  return CameraRig::LoadKalibr(SourcePath(file), robot.FramePose(RobotFrames::CameraOptical(0)));
}

double HeadingDegrees(const Eigen::Isometry3d& T_base_camera) {
  const Eigen::Vector3d axis = T_base_camera.linear().col(2);
  return std::atan2(axis.y(), axis.x()) * 180.0 / M_PI;
}

double AngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

TEST(RobotDescription, DriveGeometryComesFromTheWheels) {
  const auto robot = LoadRobot();
  EXPECT_NEAR(robot.drive().wheel_radius, 0.115, 1e-9);
  EXPECT_NEAR(robot.drive().wheel_separation, 0.46, 1e-9);
  // Footprint ~0.7 x 0.5 m: chassis 0.70 long, wheels outside a 0.42 m chassis.
  const auto chassis = robot.urdf().getLink("base_link")->collision_array[0]->geometry;
  const auto& box = static_cast<const urdf::Box&>(*chassis);
  EXPECT_NEAR(box.dim.x, 0.70, 1e-9);
  EXPECT_NEAR(robot.drive().wheel_separation + 0.05, 0.51, 1e-9);
}

// The outline the evaluation measures clearance with: the chassis box (0.70 long, from 0.12 behind
// the axle) and the wheels' discs at +-0.23 m.
TEST(RobotDescription, BaseOutlineIsTheChassisAndTheWheels) {
  const auto [low, high] = LoadRobot().BaseOutline();
  EXPECT_NEAR(low.x(), 0.23 - 0.35, 1e-9);
  EXPECT_NEAR(high.x(), 0.23 + 0.35, 1e-9);
  EXPECT_NEAR(high.y(), 0.23 + 0.005, 1e-9);
  EXPECT_NEAR(low.y(), -high.y(), 1e-9);
}

TEST(RobotDescription, ArmHasJacoJ2n6s300Geometry) {
  const auto robot = LoadRobot();
  auto joint_origin = [&](const std::string& joint) -> Eigen::Vector3d {
    return robot.FramePose(robot.urdf().getJoint(joint)->child_link_name).translation();
  };
  EXPECT_NEAR((joint_origin("arm_joint_2") - robot.FramePose("arm_link_base").translation()).norm(),
              std::hypot(0.2755, 0.0016), 1e-6);
  EXPECT_NEAR((joint_origin("arm_joint_3") - joint_origin("arm_joint_2")).norm(), 0.410, 1e-6);
  EXPECT_NEAR((joint_origin("arm_joint_4") - joint_origin("arm_joint_3")).norm(), std::hypot(0.2073, 0.0114), 1e-6);
  EXPECT_NEAR((joint_origin("arm_joint_5") - joint_origin("arm_joint_4")).norm(), 0.0741, 1e-4);
  EXPECT_NEAR((joint_origin("arm_joint_6") - joint_origin("arm_joint_5")).norm(), 0.0741, 1e-4);
  EXPECT_NEAR((robot.FramePose("arm_end_effector").translation() - joint_origin("arm_joint_6")).norm(), 0.160, 1e-6);
  // The two wrist joint axes are 60 degrees apart.
  const Eigen::Vector3d axis4 = robot.FramePose("arm_link_4").linear().col(2);
  const Eigen::Vector3d axis5 = robot.FramePose("arm_link_5").linear().col(2);
  EXPECT_NEAR(std::acos(std::abs(axis4.dot(axis5))) * 180.0 / M_PI, 60.0, 1e-6);
  // The arm stands in the centre of the ring.
  const Eigen::Vector3d ring = robot.FramePose(RobotFrames::kCameraRing).translation();
  EXPECT_NEAR((robot.FramePose("arm_link_base").translation().head<2>() - ring.head<2>()).norm(), 0.0, 1e-9);
}

TEST(CameraRig, NominalCalibrationAgreesWithUrdfCameraFrames) {
  const auto robot = LoadRobot();
  const auto rig = LoadRig(robot, "robot/calibration/nominal_camchain.yaml");
  ASSERT_EQ(rig.size(), 10);
  for (int i = 0; i < rig.size(); ++i) {
    const Eigen::Isometry3d urdf = robot.FramePose(RobotFrames::CameraOptical(i));
    const Eigen::Isometry3d calibrated = rig.camera(i).T_base_camera;
    EXPECT_LT((urdf.translation() - calibrated.translation()).norm(), 1e-5) << "cam" << i;
    EXPECT_LT(AngleBetween(urdf.linear(), calibrated.linear()), 1e-6) << "cam" << i;
  }
}

TEST(CameraRig, NominalRingHasTheDesignGeometry) {
  const auto robot = LoadRobot();
  const auto rig = LoadRig(robot, "robot/calibration/nominal_camchain.yaml");
  const Eigen::Vector3d ring = robot.FramePose(RobotFrames::kCameraRing).translation();
  for (const auto& pair : rig.StereoPairs()) {
    EXPECT_NEAR(pair.baseline, 0.03, 1e-9);
    const auto& left = rig.camera(pair.left);
    const auto& right = rig.camera(pair.right);
    const Eigen::Vector3d centre = 0.5 * (left.T_base_camera.translation() + right.T_base_camera.translation());
    EXPECT_NEAR((centre - ring).head<2>().norm(), 0.075, 1e-9);
    EXPECT_NEAR(centre.z(), 0.49, 1e-9);
    // Pair k looks along yaw 72k degrees; optical axes horizontal; the left camera is on the left.
    EXPECT_NEAR(std::remainder(HeadingDegrees(left.T_base_camera) - 72.0 * (pair.left / 2), 360.0), 0.0, 1e-9);
    EXPECT_NEAR(left.T_base_camera.linear().col(2).z(), 0.0, 1e-12);
    const Eigen::Vector3d right_in_left = left.T_base_camera.inverse() * right.T_base_camera.translation();
    EXPECT_NEAR(right_in_left.x(), 0.03, 1e-9);  // right camera along +x (image right) of the left one
    EXPECT_NEAR(left.intrinsics.HorizontalFovDegrees(), 82.0, 8.0);  // radtan widens the 69 deg pinhole
  }
}

TEST(CameraRig, RealCalibrationLoadsWithTheRingGeometry) {
  const auto robot = LoadRobot();
  const auto rig = LoadRig(robot, "robot/calibration/trimbot2020_camchain.yaml");
  ASSERT_EQ(rig.size(), 10);
  const auto pairs = rig.StereoPairs();
  ASSERT_EQ(pairs.size(), 5u);
  for (const auto& pair : pairs) {
    EXPECT_GT(pair.baseline, 0.028);
    EXPECT_LT(pair.baseline, 0.031);
    const double heading = HeadingDegrees(rig.camera(pair.left).T_base_camera);
    EXPECT_NEAR(std::remainder(heading - 72.0 * (pair.left / 2), 360.0), 0.0, 3.0) << "pair " << pair.left / 2;
    EXPECT_LT(std::abs(rig.camera(pair.left).T_base_camera.linear().col(2).z()), 0.05);
    EXPECT_NEAR(rig.camera(pair.left).intrinsics.fx, 540.0, 10.0);
  }
  // Writing and reading back reproduces the chain.
  const std::string copy = testing::WriteTempFile("real_roundtrip.yaml", rig.ToKalibrYaml());
  const auto again = CameraRig::LoadKalibr(copy, rig.camera(0).T_base_camera);
  for (int i = 0; i < rig.size(); ++i) {
    EXPECT_LT((again.camera(i).T_base_camera.translation() - rig.camera(i).T_base_camera.translation()).norm(), 1e-9);
    EXPECT_NEAR(again.camera(i).intrinsics.k1, rig.camera(i).intrinsics.k1, 1e-12);
  }
}

TEST(CameraRig, ProjectionMatchesOpenCV) {
  const auto robot = LoadRobot();
  const auto rig = LoadRig(robot, "robot/calibration/trimbot2020_camchain.yaml");
  const auto& in = rig.camera(3).intrinsics;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> lateral(-0.8, 0.8), depth(0.5, 10.0);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 200; ++i) {
    const double z = depth(rng);
    points.emplace_back(lateral(rng) * z, lateral(rng) * z * 0.6, z);
  }
  std::vector<cv::Point2d> expected;
  const cv::Matx33d K(in.fx, 0, in.cx, 0, in.fy, in.cy, 0, 0, 1);
  const std::vector<double> distortion = {in.k1, in.k2, in.p1, in.p2};
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, distortion, expected);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d pixel = in.Project({points[i].x, points[i].y, points[i].z});
    EXPECT_NEAR(pixel.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(pixel.y(), expected[i].y, 1e-9);
    // Undistort inverts the projection everywhere in the image.
    const Eigen::Vector2d ray = in.Undistort(pixel);
    EXPECT_NEAR(ray.x(), points[i].x / points[i].z, 1e-9);
    EXPECT_NEAR(ray.y(), points[i].y / points[i].z, 1e-9);
  }
}

// ---- bad input: every error names the file and the problem ----

void ExpectInputError(const std::function<void()>& load, const std::string& file, const std::string& problem) {
  try {
    load();
    FAIL() << "expected an InputError about " << problem;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
  }
}

TEST(BadInput, MissingAndMalformedUrdf) {
  ExpectInputError([] { RobotDescription::Load("/nonexistent/robot.urdf"); }, "/nonexistent/robot.urdf", "not found");
  const std::string broken = testing::WriteTempFile("broken.urdf", "<robot name='x'><link name='base_link'>");
  ExpectInputError([&] { RobotDescription::Load(broken); }, broken, "malformed URDF");
  const std::string no_camera =
      testing::WriteTempFile("no_camera.urdf", "<robot name='x'><link name='base_link'/></robot>");
  ExpectInputError([&] { RobotDescription::Load(no_camera); }, no_camera, "missing link");
}

TEST(BadInput, MalformedCalibration) {
  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  ExpectInputError([&] { CameraRig::LoadKalibr("/nonexistent/camchain.yaml", identity); }, "/nonexistent/camchain.yaml",
                   "not found");
  const std::string header =
      "cam0:\n  camera_model: pinhole\n  distortion_model: radtan\n  distortion_coeffs: [0, 0, 0, 0]\n"
      "  resolution: [752, 480]\n";
  const std::string no_intrinsics = testing::WriteTempFile("no_intrinsics.yaml", header);
  ExpectInputError([&] { CameraRig::LoadKalibr(no_intrinsics, identity); }, no_intrinsics,
                   "'cam0.intrinsics': missing");
  const std::string bad_type = testing::WriteTempFile("bad_type.yaml", header + "  intrinsics: [540, 540, abc, 240]\n");
  ExpectInputError([&] { CameraRig::LoadKalibr(bad_type, identity); }, bad_type, "expected a list of numbers");
  const std::string unknown =
      testing::WriteTempFile("unknown.yaml", header + "  intrinsics: [540, 540, 376, 240]\n  focal: 3\n");
  ExpectInputError([&] { CameraRig::LoadKalibr(unknown, identity); }, unknown, "unknown key 'cam0.focal'");
  const std::string not_rigid = testing::WriteTempFile(
      "not_rigid.yaml",
      header + "  intrinsics: [540, 540, 376, 240]\ncam1:\n  T_cn_cnm1: [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n" +
          header.substr(6) + "  intrinsics: [540, 540, 376, 240]\n");
  ExpectInputError([&] { CameraRig::LoadKalibr(not_rigid, identity); }, not_rigid, "not a rigid transform");
  const std::string broken = testing::WriteTempFile("broken_yaml.yaml", "cam0: [unclosed\n");
  ExpectInputError([&] { CameraRig::LoadKalibr(broken, identity); }, broken, "malformed YAML");
}

TEST(BadInput, RobotParametersReportLineAndKey) {
  const std::string path = testing::WriteTempFile("parameters.yaml", "imu:\n  frame: imu_link\n  rate_hz: fast\n");
  ExpectInputError([&] { robot::RobotParameters::Load(path); }, path, "line 3: key 'imu.rate_hz': expected a number");
}

}  // namespace
}  // namespace trimbot
