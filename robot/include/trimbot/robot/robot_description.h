#pragma once
// The robot description: the URDF (parsed with urdfdom) and what is derived from it — frame
// poses, the drive geometry, the arm joints. Simulator and stack read the same file.
#include <urdf_model/model.h>
#include <urdf_world/types.h>

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "trimbot/robot/diff_drive.h"

namespace trimbot::robot {

// Names the rest of the code relies on; the URDF must define them.
struct RobotFrames {
  static constexpr const char* kBase = "base_link";
  static constexpr const char* kImu = "imu_link";
  static constexpr const char* kCameraRing = "camera_ring_link";
  static constexpr const char* kLeftWheelJoint = "left_wheel_joint";
  static constexpr const char* kRightWheelJoint = "right_wheel_joint";
  static constexpr const char* kLeftWheelLink = "left_wheel_link";
  static constexpr const char* kEndEffector = "arm_end_effector";
  static constexpr const char* kCutterJoint = "cutter_blade_joint";
  static std::string CameraOptical(int index) { return "cam" + std::to_string(index) + "_optical_frame"; }
  static std::string ArmJoint(int index) { return "arm_joint_" + std::to_string(index + 1); }
};

// A link's collision cylinder: its axis' end points in the link's frame, and its radius.
struct LinkCylinder {
  std::string link;
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

class RobotDescription {
 public:
  // Throws InputError naming the file if it is missing, malformed, or lacks a required frame.
  static RobotDescription Load(const std::string& urdf_path);

  const urdf::ModelInterface& urdf() const { return *model_; }
  const std::string& path() const { return path_; }

  // Pose of a link in base_link with every joint at the given position (default zero).
  Eigen::Isometry3d FramePose(const std::string& link, const std::map<std::string, double>& joint_positions = {}) const;
  // The cutter blade's frame (the child of cutter_blade_joint: the disc about its z axis) in the
  // cutter frame (arm_end_effector), the blade at zero turn.
  Eigen::Isometry3d BladeInCutter() const;
  // The blade disc's radius and thickness (m): its link's collision cylinder.
  double BladeRadius() const;
  double BladeThickness() const;
  // Pose of a child link in its parent link for the joint at position q.
  static Eigen::Isometry3d JointTransform(const urdf::Joint& joint, double q);

  DiffDriveGeometry drive() const { return drive_; }
  std::vector<std::string> ArmJointNames() const;
  // The collision cylinders of the links the arm's joints move (links 1-6, the cutter's housing
  // included; the blade is the cutter joint's, not among them): what must keep out of the leaves.
  // Throws InputError naming the file and link when one has no collision cylinder.
  std::vector<LinkCylinder> ArmLinkCylinders() const;
  // The base's outline on the ground: the xy bounding box in base_link (min, max) of the collision
  // geometry of base_link and the wheels (what touches a bush or an obstacle first; the ring and
  // the arm at rest stand within it).
  std::pair<Eigen::Vector2d, Eigen::Vector2d> BaseOutline() const;
  // The highest point of the robot's collision geometry above base_link with the joints at these
  // positions (the bounding boxes of boxes, cylinders and spheres): what passes under a tree crown.
  double Top(const std::map<std::string, double>& joint_positions = {}) const;

 private:
  const urdf::Cylinder& BladeCylinder() const;  // InputError when the blade's link has none

  std::string path_;
  urdf::ModelInterfaceSharedPtr model_;
  DiffDriveGeometry drive_;
};

Eigen::Isometry3d ToIsometry(const urdf::Pose& pose);

}  // namespace trimbot::robot
