#include "trimbot/sim/robot_mjcf.h"

#include <filesystem>
#include <sstream>

#include "mjcf_text.h"
#include "trimbot/common/input_error.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/sim/render_pinhole.h"

namespace trimbot::sim {
namespace {

using garden::ObjectClass;
using mjcf::Num;
using mjcf::PoseAttributes;
using mjcf::Vec;
using robot::RobotFrames;

// MuJoCo cameras look along -z with y up; optical frames look along +z with y down.
Eigen::Isometry3d OpticalToMujocoCamera(const Eigen::Isometry3d& optical) {
  Eigen::Isometry3d out = optical;
  out.linear() = optical.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return out;
}

// The robot's body tree: the URDF's links as bodies (frame-only links as sites), the cameras
// under the ring at their calibrated poses.
class MjcfEmitter {
 public:
  MjcfEmitter(const robot::RobotDescription& robot, const robot::CameraRig& rig, double oversampling)
      : robot_(robot), rig_(rig), oversampling_(oversampling) {}

  std::string RobotBody(const Pose2& start) {
    const auto& root = *robot_.urdf().getRoot();
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() << start.x, start.y, 0.0;
    pose.linear() = Eigen::AngleAxisd(start.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    out_ << "    <body name=\"" << root.name << "\" " << PoseAttributes(pose) << " childclass=\"robot\">\n"
         << "      <freejoint name=\"base_free\"/>\n";
    LinkContents(root, 6);
    out_ << "    </body>\n";
    return out_.str();
  }
  const std::vector<GeomLabel>& labels() const { return labels_; }

 private:
  static bool IsFrameOnly(const urdf::Link& link) {
    return link.visual_array.empty() && link.collision_array.empty() && !link.inertial && link.child_links.empty();
  }

  void Geom(const urdf::Geometry& geometry, const urdf::Pose& origin, const std::string& name,
            const std::string& geom_class, const std::string& extra, int indent) {
    std::string type, size;
    switch (geometry.type) {
      case urdf::Geometry::BOX: {
        const auto& box = static_cast<const urdf::Box&>(geometry);
        type = "box";
        size = Num(box.dim.x / 2) + " " + Num(box.dim.y / 2) + " " + Num(box.dim.z / 2);
        break;
      }
      case urdf::Geometry::CYLINDER: {
        const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
        type = "cylinder";
        size = Num(cylinder.radius) + " " + Num(cylinder.length / 2);
        break;
      }
      case urdf::Geometry::SPHERE:
        type = "sphere";
        size = Num(static_cast<const urdf::Sphere&>(geometry).radius);
        break;
      default:
        throw InputError(robot_.path(), "geom '" + name + "': only box, cylinder and sphere geometry is supported");
    }
    out_ << std::string(indent, ' ') << "<geom name=\"" << name << "\" class=\"" << geom_class << "\" type=\"" << type
         << "\" size=\"" << size << "\" " << PoseAttributes(robot::ToIsometry(origin)) << extra << "/>\n";
    labels_.push_back({name, ObjectClass::kRobot, garden::kRobotObjectId, false, garden::Surface::kGrass});
  }

  // Whether an arm joint lies between the link and the root: its geoms may hit the robot itself.
  static bool MovesWithArm(const urdf::Link& link) {
    const urdf::Link* current = &link;
    while (current->parent_joint) {
      if (current->parent_joint->name.rfind("arm_joint_", 0) == 0) return true;
      current = current->getParent().get();
    }
    return false;
  }

  void LinkContents(const urdf::Link& link, int indent) {
    const std::string pad(indent, ' ');
    if (link.inertial) {
      // MJCF takes either an orientation or a full tensor: rotate the tensor into the body frame.
      const auto& in = *link.inertial;
      const Eigen::Isometry3d origin = robot::ToIsometry(in.origin);
      Eigen::Matrix3d inertia;
      inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
      inertia = origin.linear() * inertia * origin.linear().transpose();
      out_ << pad << "<inertial pos=\"" << Vec(origin.translation()) << "\" mass=\"" << Num(in.mass)
           << "\" fullinertia=\"" << Num(inertia(0, 0)) << " " << Num(inertia(1, 1)) << " " << Num(inertia(2, 2)) << " "
           << Num(inertia(0, 1)) << " " << Num(inertia(0, 2)) << " " << Num(inertia(1, 2)) << "\"/>\n";
    }
    for (size_t i = 0; i < link.visual_array.size(); ++i) {
      const auto& visual = *link.visual_array[i];
      std::string rgba;
      if (visual.material) {
        const auto& c = visual.material->color;
        rgba = " rgba=\"" + Num(c.r) + " " + Num(c.g) + " " + Num(c.b) + " " + Num(c.a) + "\"";
      }
      Geom(*visual.geometry, visual.origin, link.name + "/visual" + std::to_string(i), "visual", rgba, indent);
    }
    for (size_t i = 0; i < link.collision_array.size(); ++i) {
      const auto& collision = *link.collision_array[i];
      // The passive front support is a skid: frictionless, and its settings win over the ground's.
      const std::string extra = collision.name == "front_support" ? " condim=\"1\" priority=\"1\"" : "";
      Geom(*collision.geometry, collision.origin, link.name + "/collision" + std::to_string(i),
           MovesWithArm(link) ? "arm_collision" : "collision", extra, indent);
    }
    if (link.name == RobotFrames::kCameraRing) Cameras(indent);
    for (const auto& child : link.child_links) ChildLink(*child, indent);
  }

  void ChildLink(const urdf::Link& link, int indent) {
    const std::string pad(indent, ' ');
    const auto& joint = *link.parent_joint;
    const Eigen::Isometry3d origin = robot::ToIsometry(joint.parent_to_joint_origin_transform);
    if (link.name.rfind("cam", 0) == 0 && link.name.find("_optical_frame") != std::string::npos) {
      return;  // cameras are placed from the calibration (see Cameras)
    }
    if (joint.type == urdf::Joint::FIXED && IsFrameOnly(link)) {
      out_ << pad << "<site name=\"" << link.name << "\" " << PoseAttributes(origin) << "/>\n";
      return;
    }
    out_ << pad << "<body name=\"" << link.name << "\" " << PoseAttributes(origin) << ">\n";
    switch (joint.type) {
      case urdf::Joint::FIXED:
        break;
      case urdf::Joint::REVOLUTE:
      case urdf::Joint::CONTINUOUS: {
        out_ << pad << "  <joint name=\"" << joint.name << "\" type=\"hinge\" axis=\"" << Num(joint.axis.x) << " "
             << Num(joint.axis.y) << " " << Num(joint.axis.z) << "\"";
        if (joint.type == urdf::Joint::REVOLUTE && joint.limits) {
          out_ << " limited=\"true\" range=\"" << Num(joint.limits->lower) << " " << Num(joint.limits->upper) << "\"";
        }
        out_ << " class=\"" << (joint.name.rfind("arm_", 0) == 0 ? "arm_joint" : "drive_joint") << "\"/>\n";
        break;
      }
      default:
        throw InputError(robot_.path(),
                         "joint '" + joint.name + "': only fixed, revolute and continuous joints are supported");
    }
    LinkContents(link, indent + 2);
    out_ << pad << "</body>\n";
  }

  // Cameras at the calibrated poses, expressed in camera_ring_link.
  void Cameras(int indent) {
    const Eigen::Isometry3d T_base_ring = robot_.FramePose(RobotFrames::kCameraRing);
    for (const auto& cam : rig_.cameras()) {
      const Eigen::Isometry3d T_ring_cam = T_base_ring.inverse() * cam.T_base_camera;
      const RenderPinhole render = RenderPinholeFor(cam.intrinsics, oversampling_);
      out_ << std::string(indent, ' ') << "<camera name=\"" << cam.name << "\" "
           << PoseAttributes(OpticalToMujocoCamera(T_ring_cam)) << " fovy=\"" << Num(render.fovy_degrees) << "\"/>\n";
    }
  }

  const robot::RobotDescription& robot_;
  const robot::CameraRig& rig_;
  double oversampling_;
  std::ostringstream out_;
  std::vector<GeomLabel> labels_;
};

// The robot's default classes. Bits: 1 garden, 2 robot, 4 arm. The robot hits the garden; the arm
// also hits the robot (MuJoCo skips bodies welded together and parent-child pairs: the URDF's
// adjacent links).
constexpr const char* kDefaults =
    "  <default>\n"
    "    <default class=\"robot\">\n"
    "      <default class=\"visual\"><geom contype=\"0\" conaffinity=\"0\" group=\"1\"/></default>\n"
    "      <default class=\"collision\"><geom contype=\"2\" conaffinity=\"5\" group=\"3\" friction=\"0.5 0.005 "
    "0.0001\"/>\n"
    "        <default class=\"arm_collision\"><geom contype=\"6\" conaffinity=\"5\"/></default>\n"
    "      </default>\n"
    "      <default class=\"drive_joint\"><joint damping=\"0.01\" armature=\"0.01\"/></default>\n"
    "      <default class=\"arm_joint\"><joint damping=\"3\" armature=\"0.05\"/></default>\n"
    "    </default>\n"
    "  </default>\n";

// Wheel velocity motors and arm position servos within the URDF's effort limits, the cutter's motor.
std::string Actuators(const robot::RobotDescription& robot) {
  std::ostringstream xml;
  xml << "  <actuator>\n";
  for (const char* wheel : {RobotFrames::kLeftWheelJoint, RobotFrames::kRightWheelJoint}) {
    const auto joint = robot.urdf().getJoint(wheel);
    const double effort = joint->limits ? joint->limits->effort : 20.0;
    xml << "    <velocity name=\"" << wheel << "_motor\" joint=\"" << wheel << "\" kv=\"20\" forcelimited=\"true\" "
        << "forcerange=\"" << Num(-effort) << " " << Num(effort) << "\"/>\n";
  }
  for (const auto& name : robot.ArmJointNames()) {
    const auto joint = robot.urdf().getJoint(name);
    const double effort = joint->limits ? joint->limits->effort : 20.0;
    xml << "    <position name=\"" << name << "_servo\" joint=\"" << name << "\" kp=\"150\" forcelimited=\"true\" "
        << "forcerange=\"" << Num(-effort) << " " << Num(effort) << "\"/>\n";
  }
  xml << "    <velocity name=\"cutter_motor\" joint=\"" << RobotFrames::kCutterJoint << "\" kv=\"0.01\"/>\n"
      << "  </actuator>\n";
  return xml.str();
}

std::string FileName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

}  // namespace

RobotMjcf ComposeRobot(const robot::RobotDescription& robot, const robot::CameraRig& rig,
                       const RobotMjcfOptions& options) {
  MjcfEmitter emitter(robot, rig, options.render_oversampling);
  const std::string body = emitter.RobotBody(options.start);
  std::ostringstream xml;
  xml << "<mujoco model=\"" << robot.urdf().getName() << "\">\n"
      << "  <!-- Composed by sim/robot_mjcf from " << FileName(robot.path()) << " and " << FileName(rig.source())
      << "; start x y yaw " << Num(options.start.x) << " " << Num(options.start.y) << " " << Num(options.start.yaw)
      << ", render oversampling " << Num(options.render_oversampling)
      << ". -->\n"
      // The URDF's angles are in radians and its links carry their inertia.
      << "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
      // The servos and the wheel motors' gains are for the implicit integrator.
      << "  <option integrator=\"implicit\"/>\n"
      << kDefaults << "  <worldbody>\n"
      << body << "  </worldbody>\n"
      << Actuators(robot) << "  <sensor>\n"
      << "    <accelerometer name=\"imu_accelerometer\" site=\"" << RobotFrames::kImu << "\"/>\n"
      << "    <gyro name=\"imu_gyro\" site=\"" << RobotFrames::kImu << "\"/>\n"
      << "  </sensor>\n"
      << "</mujoco>\n";
  return {xml.str(), emitter.labels()};
}

std::string NominalRobotMjcf(const std::string& robot_dir) {
  const robot::RobotFiles files = robot::RobotFiles::InFolder(robot_dir);
  return ComposeRobot(robot::RobotDescription::Load(files.urdf), robot::LoadCameraRig(files)).xml;
}

}  // namespace trimbot::sim
