#include "trimbot/robot/robot_description.h"

#include <limits>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <filesystem>
#include <mutex>
#include <optional>

#include "trimbot/common/input_error.h"

namespace trimbot::robot {
namespace {

// urdfdom reports parse errors through console_bridge; collect them so the InputError can say
// what was wrong instead of "see above".
class CollectingHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) messages += (messages.empty() ? "" : "; ") + text;
  }
  std::string messages;
};

std::mutex parse_mutex;  // console_bridge's handler is global

// Half extents of a collision geometry's own bounding box (boxes, cylinders, spheres; none for
// meshes, which the robot's collision model does not use).
std::optional<Eigen::Vector3d> HalfExtents(const urdf::Geometry& g) {
  if (g.type == urdf::Geometry::BOX) {
    const auto& box = static_cast<const urdf::Box&>(g);
    return 0.5 * Eigen::Vector3d(box.dim.x, box.dim.y, box.dim.z);
  }
  if (g.type == urdf::Geometry::CYLINDER) {
    const auto& cylinder = static_cast<const urdf::Cylinder&>(g);
    return Eigen::Vector3d(cylinder.radius, cylinder.radius, 0.5 * cylinder.length);
  }
  if (g.type == urdf::Geometry::SPHERE) return Eigen::Vector3d::Constant(static_cast<const urdf::Sphere&>(g).radius);
  return std::nullopt;
}

// A link's collision geometry when it is a cylinder, else nullptr.
const urdf::Cylinder* CollisionCylinder(const urdf::LinkConstSharedPtr& link) {
  return link && link->collision && link->collision->geometry
             ? dynamic_cast<const urdf::Cylinder*>(link->collision->geometry.get())
             : nullptr;
}

}  // namespace

Eigen::Isometry3d ToIsometry(const urdf::Pose& pose) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() << pose.position.x, pose.position.y, pose.position.z;
  t.linear() = Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  return t;
}

RobotDescription RobotDescription::Load(const std::string& urdf_path) {
  if (!std::filesystem::is_regular_file(urdf_path)) throw InputError(urdf_path, "URDF file not found");
  RobotDescription out;
  out.path_ = urdf_path;
  {
    std::lock_guard<std::mutex> lock(parse_mutex);
    CollectingHandler handler;
    console_bridge::useOutputHandler(&handler);
    out.model_ = urdf::parseURDFFile(urdf_path);
    console_bridge::restorePreviousOutputHandler();
    if (!out.model_) {
      throw InputError(urdf_path, "malformed URDF: " + (handler.messages.empty() ? "parse failed" : handler.messages));
    }
  }
  const auto& model = *out.model_;
  if (model.getRoot() == nullptr || model.getRoot()->name != RobotFrames::kBase) {
    throw InputError(urdf_path, std::string("the root link must be '") + RobotFrames::kBase + "'");
  }
  std::vector<std::string> required_links = {RobotFrames::kImu, RobotFrames::kCameraRing, RobotFrames::kEndEffector,
                                             RobotFrames::kLeftWheelLink};
  for (int i = 0; i < 10; ++i) required_links.push_back(RobotFrames::CameraOptical(i));
  for (const auto& name : required_links) {
    if (!model.getLink(name)) throw InputError(urdf_path, "missing link '" + name + "'");
  }
  std::vector<std::string> required_joints = {RobotFrames::kLeftWheelJoint, RobotFrames::kRightWheelJoint,
                                              RobotFrames::kCutterJoint};
  for (int i = 0; i < 6; ++i) required_joints.push_back(RobotFrames::ArmJoint(i));
  for (const auto& name : required_joints) {
    if (!model.getJoint(name)) throw InputError(urdf_path, "missing joint '" + name + "'");
  }

  // Drive geometry from the wheel joints and the wheel's collision cylinder.
  const auto left = model.getJoint(RobotFrames::kLeftWheelJoint);
  const auto right = model.getJoint(RobotFrames::kRightWheelJoint);
  out.drive_.wheel_separation =
      left->parent_to_joint_origin_transform.position.y - right->parent_to_joint_origin_transform.position.y;
  const auto wheel = model.getLink(RobotFrames::kLeftWheelLink);
  if (!wheel->collision || !wheel->collision->geometry ||
      wheel->collision->geometry->type != urdf::Geometry::CYLINDER) {
    throw InputError(urdf_path, "left_wheel_link needs a cylinder collision geometry (the wheel radius)");
  }
  out.drive_.wheel_radius = static_cast<const urdf::Cylinder&>(*wheel->collision->geometry).radius;
  if (out.drive_.wheel_separation <= 0.0 || out.drive_.wheel_radius <= 0.0) {
    throw InputError(urdf_path, "wheel joints must sit at +y (left) and -y (right) with a positive radius");
  }
  return out;
}

Eigen::Isometry3d RobotDescription::JointTransform(const urdf::Joint& joint, double q) {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d axis(joint.axis.x, joint.axis.y, joint.axis.z);
  switch (joint.type) {
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS:
      motion.linear() = Eigen::AngleAxisd(q, axis.normalized()).toRotationMatrix();
      break;
    case urdf::Joint::PRISMATIC:
      motion.translation() = q * axis.normalized();
      break;
    default:
      break;
  }
  return ToIsometry(joint.parent_to_joint_origin_transform) * motion;
}

Eigen::Isometry3d RobotDescription::FramePose(const std::string& link,
                                              const std::map<std::string, double>& joint_positions) const {
  auto current = model_->getLink(link);
  if (!current) throw InputError(path_, "no link named '" + link + "'");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  while (current->parent_joint) {
    const auto& joint = *current->parent_joint;
    const auto q = joint_positions.find(joint.name);
    pose = JointTransform(joint, q == joint_positions.end() ? 0.0 : q->second) * pose;
    current = model_->getLink(joint.parent_link_name);
  }
  return pose;
}

Eigen::Isometry3d RobotDescription::BladeInCutter() const {
  return FramePose(RobotFrames::kEndEffector).inverse() *
         FramePose(model_->getJoint(RobotFrames::kCutterJoint)->child_link_name);
}

std::vector<LinkCylinder> RobotDescription::ArmLinkCylinders() const {
  std::vector<LinkCylinder> cylinders;
  for (const std::string& joint : ArmJointNames()) {
    const auto link = model_->getLink(model_->getJoint(joint)->child_link_name);
    const urdf::Cylinder* cylinder = CollisionCylinder(link);
    if (cylinder == nullptr) {
      throw InputError(path_,
                       "arm link '" + model_->getJoint(joint)->child_link_name +
                           "' has no collision cylinder (the arm's links are checked against the leaves as such)");
    }
    const Eigen::Isometry3d T_link_cylinder = ToIsometry(link->collision->origin);
    const Eigen::Vector3d half(0.0, 0.0, cylinder->length / 2.0);
    cylinders.push_back({link->name, T_link_cylinder * -half, T_link_cylinder * half, cylinder->radius});
  }
  return cylinders;
}

const urdf::Cylinder& RobotDescription::BladeCylinder() const {
  const urdf::Cylinder* cylinder =
      CollisionCylinder(model_->getLink(model_->getJoint(RobotFrames::kCutterJoint)->child_link_name));
  if (cylinder == nullptr) throw InputError(path_, "the cutter blade's link has no collision cylinder");
  return *cylinder;
}

double RobotDescription::BladeRadius() const { return BladeCylinder().radius; }

double RobotDescription::BladeThickness() const { return BladeCylinder().length; }

std::pair<Eigen::Vector2d, Eigen::Vector2d> RobotDescription::BaseOutline() const {
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  for (const std::string& name :
       {std::string(RobotFrames::kBase), std::string(RobotFrames::kLeftWheelLink), std::string("right_wheel_link")}) {
    const auto link = model_->getLink(name);
    if (!link) continue;
    const Eigen::Isometry3d T_base_link = FramePose(name);
    for (const auto& collision : link->collision_array) {
      if (!collision || !collision->geometry) continue;
      const std::optional<Eigen::Vector3d> extents = HalfExtents(*collision->geometry);
      if (!extents) continue;
      const Eigen::Vector3d& half = *extents;
      const Eigen::Isometry3d T = T_base_link * ToIsometry(collision->origin);
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d local((corner & 1 ? 1 : -1) * half.x(), (corner & 2 ? 1 : -1) * half.y(),
                                    (corner & 4 ? 1 : -1) * half.z());
        const Eigen::Vector2d p = (T * local).head<2>();
        low = low.cwiseMin(p);
        high = high.cwiseMax(p);
      }
    }
  }
  if (!low.allFinite()) throw InputError(path_, "base_link and the wheels have no collision geometry");
  return {low, high};
}

double RobotDescription::Top(const std::map<std::string, double>& joint_positions) const {
  double top = -std::numeric_limits<double>::infinity();
  std::vector<urdf::LinkSharedPtr> links;
  model_->getLinks(links);
  for (const auto& link : links) {
    const Eigen::Isometry3d T_base_link = FramePose(link->name, joint_positions);
    for (const auto& collision : link->collision_array) {
      if (!collision || !collision->geometry) continue;
      const std::optional<Eigen::Vector3d> extents = HalfExtents(*collision->geometry);
      if (!extents) continue;
      const Eigen::Vector3d& half = *extents;
      const Eigen::Isometry3d T = T_base_link * ToIsometry(collision->origin);
      top = std::max(top, T.translation().z() + (T.linear().row(2).cwiseAbs() * half)(0));
    }
  }
  if (!std::isfinite(top)) throw InputError(path_, "the robot has no collision geometry");
  return top;
}

std::vector<std::string> RobotDescription::ArmJointNames() const {
  std::vector<std::string> names;
  for (int i = 0; i < 6; ++i) names.push_back(RobotFrames::ArmJoint(i));
  return names;
}

}  // namespace trimbot::robot
