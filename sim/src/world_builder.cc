#include "trimbot/sim/world_builder.h"

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <set>
#include <sstream>

#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/garden/object_mesh.h"
#include "trimbot/garden/textures.h"
#include "trimbot/sim/render_pinhole.h"

namespace trimbot::sim {
namespace {

namespace fs = std::filesystem;
using garden::ObjectClass;
using robot::RobotFrames;

std::string Num(double v) {
  std::ostringstream s;
  s << std::setprecision(10) << (std::abs(v) < 1e-15 ? 0.0 : v);
  return s.str();
}

std::string Vec(const Eigen::Vector3d& v) { return Num(v.x()) + " " + Num(v.y()) + " " + Num(v.z()); }

std::string PoseAttributes(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.rotation());
  return "pos=\"" + Vec(pose.translation()) + "\" quat=\"" + Num(q.w()) + " " + Num(q.x()) + " " + Num(q.y()) +
         " " + Num(q.z()) + "\"";
}

// MuJoCo cameras look along -z with y up; optical frames look along +z with y down.
Eigen::Isometry3d OpticalToMujocoCamera(const Eigen::Isometry3d& optical) {
  Eigen::Isometry3d out = optical;
  out.linear() = optical.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return out;
}

class MjcfEmitter {
 public:
  MjcfEmitter(const robot::RobotDescription& robot, const robot::CameraRig& rig, double oversampling)
      : robot_(robot), rig_(rig), oversampling_(oversampling) {}

  std::string RobotBody(const Pose2D& start) {
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
  const std::vector<std::string>& joints() const { return joints_; }

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
    out_ << std::string(indent, ' ') << "<geom name=\"" << name << "\" class=\"" << geom_class << "\" type=\""
         << type << "\" size=\"" << size << "\" " << PoseAttributes(robot::ToIsometry(origin)) << extra << "/>\n";
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
           << "\" fullinertia=\"" << Num(inertia(0, 0)) << " " << Num(inertia(1, 1)) << " " << Num(inertia(2, 2))
           << " " << Num(inertia(0, 1)) << " " << Num(inertia(0, 2)) << " " << Num(inertia(1, 2)) << "\"/>\n";
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
        joints_.push_back(joint.name);
        break;
      }
      default:
        throw InputError(robot_.path(), "joint '" + joint.name + "': only fixed, revolute and continuous joints are supported");
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
           << PoseAttributes(OpticalToMujocoCamera(T_ring_cam)) << " fovy=\"" << Num(render.fovy_degrees)
           << "\"/>\n";
    }
  }

  const robot::RobotDescription& robot_;
  const robot::CameraRig& rig_;
  double oversampling_;
  std::ostringstream out_;
  std::vector<GeomLabel> labels_;
  std::vector<std::string> joints_;
};

// Writes the texture `name` (a material, or a ground variant: "grass_v2") into the world's folder,
// from the cache when it is there; returns its absolute path.
std::string WriteTexture(const std::string& name, const std::function<cv::Mat()>& make, std::uint64_t seed, int size,
                         const WorldOptions& options, const fs::path& dir) {
  const fs::path path = dir / (name + ".png");
  fs::path cached;
  if (!options.texture_cache_dir.empty()) {
    char key[128];
    std::snprintf(key, sizeof key, "%s_%016llx_%d_v%d.png", name.c_str(), static_cast<unsigned long long>(seed), size,
                  garden::kTextureGeneratorVersion);
    cached = fs::path(options.texture_cache_dir) / key;
    std::ifstream in(cached, std::ios::binary);
    if (in) {
      const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (!bytes.empty()) {
        WriteFileAtomically(path.string(), bytes);
        return fs::absolute(path).string();
      }
    }
  }
  std::vector<uchar> png;
  cv::imencode(".png", make(), png);
  const std::string bytes(png.begin(), png.end());
  WriteFileAtomically(path.string(), bytes);
  if (!cached.empty()) {
    try {  // a cache that cannot be written only costs time
      fs::create_directories(cached.parent_path());
      WriteFileAtomically(cached.string(), bytes);
    } catch (const std::exception&) {
    }
  }
  return fs::absolute(path).string();
}

// Ground tiles cover 2-4 m and are seen from 0.5 m up: they get twice the resolution.
int TextureSize(garden::Material material, const WorldOptions& options) {
  return garden::IsGround(material) ? 2 * options.texture_size : options.texture_size;
}

// The MJCF assets of the garden's textures and their materials, the textures written to
// `texture_dir`: one per material the paths and objects use, and the lawn's ground variants
// ("grass_v0" ...; the lawn's base tile only if a path shows it). Meshes carry their own texture
// coordinates.
std::string TextureAssets(const garden::Garden& garden, const WorldOptions& options, const fs::path& texture_dir) {
  const garden::Material lawn = garden::GroundMaterial(garden.ground);
  std::set<garden::Material> materials;
  for (const auto& path : garden.paths) materials.insert(garden::GroundMaterial(path.surface));
  for (const auto& object : garden.objects) materials.insert(garden::MaterialOf(object.object_class));
  std::ostringstream assets;
  assets << "    <texture name=\"sky\" type=\"skybox\" builtin=\"gradient\" rgb1=\"0.55 0.70 0.92\" "
            "rgb2=\"0.92 0.95 1.0\" width=\"256\" height=\"256\"/>\n";
  // A texture and the material of the same name showing it.
  const auto add_texture = [&](const std::string& name, int size, const std::function<cv::Mat()>& make) {
    const std::string file = WriteTexture(name, make, garden.appearance_seed, size, options, texture_dir);
    assets << "    <texture name=\"" << name << "\" type=\"2d\" file=\"" << file << "\"/>\n"
           << "    <material name=\"" << name << "\" texture=\"" << name << "\" specular=\"0.05\" shininess=\"0.05\"/>\n";
  };
  for (const auto material : materials) {
    const int size = TextureSize(material, options);
    add_texture(garden::ToString(material), size, [&] { return garden::MakeTexture(material, garden.appearance_seed, size); });
  }
  const int lawn_size = TextureSize(lawn, options);
  std::vector<cv::Mat> variants;  // made once, and only when one of them is not in the cache
  for (int k = 0; k < garden::kGroundVariants; ++k) {
    add_texture(garden::ToString(lawn) + "_v" + std::to_string(k), lawn_size, [&] {
      if (variants.empty()) variants = garden::MakeGroundVariants(lawn, garden.appearance_seed, lawn_size);
      return variants[static_cast<std::size_t>(k)];
    });
  }
  return assets.str();
}

}  // namespace

std::string DefaultTextureCacheDir() {
  if (const char* dir = std::getenv("TRIMBOT_TEXTURE_CACHE")) return dir;
  std::error_code error;
  const fs::path temp = fs::temp_directory_path(error);
  return error ? std::string() : (temp / "trimbot_texture_cache").string();
}

WorldSpec ComposeWorld(const robot::RobotDescription& robot, const robot::CameraRig& rig,
                       const garden::Garden& garden, const WorldOptions& options, const std::string& output_dir) {
  const fs::path dir = fs::path(output_dir);
  const fs::path texture_dir = dir / "textures";
  fs::create_directories(texture_dir);

  WorldSpec spec;
  MjcfEmitter emitter(robot, rig, options.render_oversampling);
  const std::string robot_body = emitter.RobotBody(options.start);
  spec.labels = emitter.labels();
  for (const auto& cam : rig.cameras()) spec.camera_names.push_back(cam.name);

  int max_render_w = 0, max_render_h = 0;
  for (const auto& cam : rig.cameras()) {
    const RenderPinhole render = RenderPinholeFor(cam.intrinsics, options.render_oversampling);
    max_render_w = std::max(max_render_w, render.width);
    max_render_h = std::max(max_render_h, render.height);
  }

  const garden::Material lawn = garden::GroundMaterial(garden.ground);
  std::ostringstream assets;
  assets << TextureAssets(garden, options, texture_dir);

  // Garden geometry: static geoms in the world body; objects and paths are meshes.
  std::ostringstream world;
  const double margin = 60.0;  // the lawn runs on past the garden so the horizon is not sky
  const garden::SurfaceProperties ground = garden::PropertiesOf(garden.ground);
  // The ground collides as a plane and is drawn as the lawn's patches on it (group 3: not drawn).
  const Eigen::Vector2d half(garden.size.x() / 2 + margin, garden.size.y() / 2 + margin);
  world << "    <geom name=\"garden/ground\" class=\"garden\" group=\"3\" type=\"plane\" pos=\"" << Num(garden.centre.x())
        << " " << Num(garden.centre.y()) << " 0\" size=\"" << Num(half.x()) << " " << Num(half.y()) << " 0.1\" friction=\""
        << Num(ground.friction) << " 0.005 0.0001\"/>\n";
  spec.labels.push_back({"garden/ground", ObjectClass::kGround, garden::kGroundObjectId, true, garden.ground});
  auto emit_mesh = [&](const std::string& name, const garden::Mesh& mesh, const Eigen::Matrix4d& pose,
                       const std::string& material, const std::string& geom_class) {
    assets << "    <mesh name=\"" << name << "\" vertex=\"";
    for (const auto& v : mesh.vertices) assets << Num(v.x()) << ' ' << Num(v.y()) << ' ' << Num(v.z()) << ' ';
    assets << "\" texcoord=\"";
    for (const auto& t : mesh.texcoords) assets << Num(t.x()) << ' ' << Num(t.y()) << ' ';
    assets << "\" face=\"";
    for (const auto& f : mesh.faces) assets << f[0] << ' ' << f[1] << ' ' << f[2] << ' ';
    assets << "\"/>\n";
    Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
    iso.matrix() = pose;
    world << "    <geom name=\"" << name << "\" class=\"" << geom_class << "\" type=\"mesh\" mesh=\"" << name
          << "\" " << PoseAttributes(iso) << " material=\"" << material << "\"/>\n";
  };
  // The lawn's variants at twice the tile: 4 mm a texel for grass, the scale the lawn had as a
  // plane (MuJoCo's texrepeat on a plane counts repeats per 2 m) and that the localization figures
  // were measured at; at 2 mm the blades are finer than a camera pixel and the lawn renders smooth.
  const std::vector<garden::Mesh> lawn_meshes = garden::LawnMeshes(
      garden.centre - half, garden.centre + half, 2.0 * garden::TileSize(lawn), garden.appearance_seed);
  for (std::size_t k = 0; k < lawn_meshes.size(); ++k) {
    if (lawn_meshes[k].faces.empty()) continue;
    const std::string name = "garden/lawn_v" + std::to_string(k);
    emit_mesh(name, lawn_meshes[k], Eigen::Matrix4d::Identity(), garden::ToString(lawn) + "_v" + std::to_string(k),
              "garden_surface");
    spec.labels.push_back({name, ObjectClass::kGround, garden::kGroundObjectId, true, garden.ground});
  }
  // Paths and beds are flush with the lawn: slabs whose top is 2 mm above it (deep below it, see
  // kGroundSlabDepth) that do not collide (a slab edge would stop a wheel); the simulator finds the
  // surface under a wheel from the garden's paths.
  for (size_t i = 0; i < garden.paths.size(); ++i) {
    const auto& path = garden.paths[i];
    const garden::Material material = garden::GroundMaterial(path.surface);
    const std::string name = "garden/path" + std::to_string(i) + "_" + garden::ToString(path.surface);
    garden::GardenObject slab;
    slab.position = path.centre;
    slab.yaw = path.yaw;
    slab.base_height = 0.002 - garden::kGroundSlabDepth;
    emit_mesh(name, garden::BoxMesh({path.size.x(), path.size.y(), garden::kGroundSlabDepth}, garden::TileSize(material)),
              garden::ObjectPose(slab), garden::ToString(material), "garden_surface");
    spec.labels.push_back({name, ObjectClass::kGround, garden::kGroundObjectId, true, path.surface});
  }
  for (const auto& object : garden.objects) {
    const std::string name = "garden/" + std::to_string(object.id) + "_" + garden::ToString(object.object_class);
    emit_mesh(name, garden::ObjectMesh(object, garden.appearance_seed, options.conditions.growth), garden::ObjectPose(object),
              garden::ToString(garden::MaterialOf(object.object_class)), "garden");
    spec.labels.push_back({name, object.object_class, static_cast<std::uint16_t>(object.id), false, garden.ground});
  }

  // The sun: a directional light from (azimuth, elevation) of the run's conditions; the sky fills.
  const garden::Sun sun = garden::SunFor(garden, options.conditions);
  const Eigen::Vector3d towards_sun(std::cos(sun.elevation) * std::cos(sun.azimuth),
                                    std::cos(sun.elevation) * std::sin(sun.azimuth), std::sin(sun.elevation));
  const Eigen::Vector3d sun_colour = sun.colour * sun.intensity;
  const double shadow_extent = garden.size.norm() / 2.0 + 5.0;

  std::ostringstream xml;
  xml << "<mujoco model=\"trimbot_in_" << garden.name << "\">\n"
      << "  <!-- Composed by sim/world_builder from " << robot.path() << ", " << rig.source() << " and "
      << garden.source << ". -->\n"
      << "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
      << "  <option timestep=\"" << Num(options.timestep) << "\" integrator=\"implicit\"/>\n"
      // extent 1 makes znear/zfar/shadowclip read in metres.
      << "  <statistic center=\"" << Num(garden.centre.x()) << " " << Num(garden.centre.y()) << " 0\" extent=\"1\"/>\n"
      << "  <visual>\n"
      << "    <global offwidth=\"" << max_render_w << "\" offheight=\"" << max_render_h << "\"/>\n"
      << "    <quality shadowsize=\"2048\" offsamples=\"" << options.msaa_samples << "\"/>\n"
      << "    <map znear=\"0.02\" zfar=\"80\" shadowclip=\"" << Num(shadow_extent) << "\"/>\n"
      << "    <headlight active=\"0\" ambient=\"0 0 0\" diffuse=\"0 0 0\" specular=\"0 0 0\"/>\n"
      << "  </visual>\n"
      << "  <default>\n"
      << "    <default class=\"robot\">\n"
      << "      <default class=\"visual\"><geom contype=\"0\" conaffinity=\"0\" group=\"1\"/></default>\n"
      // Bits: 1 garden, 2 robot, 4 arm. The robot hits the garden; the arm also hits the robot
      // (MuJoCo skips bodies welded together and parent-child pairs: the URDF's adjacent links).
      << "      <default class=\"collision\"><geom contype=\"2\" conaffinity=\"5\" group=\"3\" friction=\"0.5 0.005 0.0001\"/>\n"
      << "        <default class=\"arm_collision\"><geom contype=\"6\" conaffinity=\"5\"/></default>\n"
      << "      </default>\n"
      << "      <default class=\"drive_joint\"><joint damping=\"0.01\" armature=\"0.01\"/></default>\n"
      << "      <default class=\"arm_joint\"><joint damping=\"3\" armature=\"0.05\"/></default>\n"
      << "    </default>\n"
      << "    <default class=\"garden\"><geom contype=\"1\" conaffinity=\"2\" group=\"0\"/></default>\n"
      << "    <default class=\"garden_surface\"><geom contype=\"0\" conaffinity=\"0\" group=\"0\"/></default>\n"
      << "  </default>\n"
      << "  <asset>\n"
      << assets.str() << "  </asset>\n"
      << "  <worldbody>\n"
      << "    <light name=\"sun\" directional=\"true\" castshadow=\"" << (sun.shadows ? "true" : "false") << "\" pos=\""
      << Vec(towards_sun * 20.0) << "\" dir=\"" << Vec(-towards_sun) << "\" diffuse=\"" << Vec(sun_colour)
      << "\" specular=\"0.1 0.1 0.1\"/>\n"
      << "    <light name=\"sky\" directional=\"true\" castshadow=\"false\" pos=\"0 0 20\" dir=\"0 0 -1\" "
         "diffuse=\"0.15 0.16 0.18\" ambient=\"" << Vec(sun.ambient) << "\" specular=\"0 0 0\"/>\n"
      << world.str() << robot_body << "  </worldbody>\n"
      << "  <actuator>\n";
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
      << "  </actuator>\n"
      << "  <sensor>\n"
      << "    <accelerometer name=\"imu_accelerometer\" site=\"" << RobotFrames::kImu << "\"/>\n"
      << "    <gyro name=\"imu_gyro\" site=\"" << RobotFrames::kImu << "\"/>\n"
      << "  </sensor>\n"
      << "</mujoco>\n";

  spec.mjcf_path = fs::absolute(dir / "world.xml").string();
  WriteFileAtomically(spec.mjcf_path, xml.str());
  return spec;
}

}  // namespace trimbot::sim
