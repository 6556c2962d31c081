#include "trimbot/sim/world_builder.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include "mjcf_text.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/garden/foliage.h"
#include "trimbot/garden/object_mesh.h"
#include "trimbot/garden/textures.h"
#include "trimbot/sim/render_pinhole.h"

namespace trimbot::sim {
namespace {

namespace fs = std::filesystem;
using garden::ObjectClass;
using mjcf::Num;
using mjcf::PoseAttributes;
using mjcf::Vec;

// The run's robot, beside world.xml (which includes it).
constexpr const char* kRobotFile = "robot.xml";

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
           << "    <material name=\"" << name << "\" texture=\"" << name
           << "\" specular=\"0.05\" shininess=\"0.05\"/>\n";
  };
  for (const auto material : materials) {
    const int size = TextureSize(material, options);
    add_texture(garden::ToString(material), size,
                [&] { return garden::MakeTexture(material, garden.appearance_seed, size); });
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

// The garden as static geoms in the world body: the ground plane, the lawn's patches, the paths
// and the objects (meshes, whose assets follow the textures'), with their labels.
class GardenEmitter {
 public:
  GardenEmitter(const garden::Garden& garden, const WorldOptions& options, const std::string& texture_assets)
      : garden_(garden), options_(options) {
    assets_ << texture_assets;
    const double margin = 60.0;  // the lawn runs on past the garden so the horizon is not sky
    const Eigen::Vector2d half(garden.size.x() / 2 + margin, garden.size.y() / 2 + margin);
    Ground(half);
    Lawn(half);
    Paths();
    Objects();
  }
  std::string assets() const { return assets_.str(); }
  std::string geoms() const { return geoms_.str(); }
  const std::vector<GeomLabel>& labels() const { return labels_; }

 private:
  // The ground collides as a plane and is drawn as the lawn's patches on it (group 3: not drawn).
  void Ground(const Eigen::Vector2d& half) {
    const garden::SurfaceProperties ground = garden::PropertiesOf(garden_.ground);
    geoms_ << "    <geom name=\"garden/ground\" class=\"garden\" group=\"3\" type=\"plane\" pos=\""
           << Num(garden_.centre.x()) << " " << Num(garden_.centre.y()) << " 0\" size=\"" << Num(half.x()) << " "
           << Num(half.y()) << " 0.1\" friction=\"" << Num(ground.friction) << " 0.005 0.0001\"/>\n";
    labels_.push_back({"garden/ground", ObjectClass::kGround, garden::kGroundObjectId, true, garden_.ground});
  }

  // `extra`: more attributes of the geom. A mesh without faces is its vertices' convex hull.
  void Mesh(const std::string& name, const garden::Mesh& mesh, const Eigen::Matrix4d& pose, const std::string& material,
            const std::string& geom_class, const std::string& extra = "") {
    assets_ << "    <mesh name=\"" << name << "\" vertex=\"";
    for (const auto& v : mesh.vertices) assets_ << Num(v.x()) << ' ' << Num(v.y()) << ' ' << Num(v.z()) << ' ';
    assets_ << "\"";
    if (!mesh.texcoords.empty()) {
      assets_ << " texcoord=\"";
      for (const auto& t : mesh.texcoords) assets_ << Num(t.x()) << ' ' << Num(t.y()) << ' ';
      assets_ << "\"";
    }
    if (!mesh.faces.empty()) {
      assets_ << " face=\"";
      for (const auto& f : mesh.faces) assets_ << f[0] << ' ' << f[1] << ' ' << f[2] << ' ';
      assets_ << "\"";
    }
    assets_ << "/>\n";
    Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
    iso.matrix() = pose;
    geoms_ << "    <geom name=\"" << name << "\" class=\"" << geom_class << "\" type=\"mesh\" mesh=\"" << name << "\" "
           << PoseAttributes(iso) << " material=\"" << material << "\"" << extra << "/>\n";
  }

  // The lawn's variants at twice the tile: 4 mm a texel for grass, the scale the lawn had as a
  // plane (MuJoCo's texrepeat on a plane counts repeats per 2 m) and that the localization figures
  // were measured at; at 2 mm the blades are finer than a camera pixel and the lawn renders smooth.
  void Lawn(const Eigen::Vector2d& half) {
    const garden::Material lawn = garden::GroundMaterial(garden_.ground);
    const std::vector<garden::Mesh> lawn_meshes = garden::LawnMeshes(
        garden_.centre - half, garden_.centre + half, 2.0 * garden::TileSize(lawn), garden_.appearance_seed);
    for (std::size_t k = 0; k < lawn_meshes.size(); ++k) {
      if (lawn_meshes[k].faces.empty()) continue;
      const std::string name = "garden/lawn_v" + std::to_string(k);
      Mesh(name, lawn_meshes[k], Eigen::Matrix4d::Identity(), garden::ToString(lawn) + "_v" + std::to_string(k),
           "garden_surface");
      labels_.push_back({name, ObjectClass::kGround, garden::kGroundObjectId, true, garden_.ground});
    }
  }

  // Paths and beds are flush with the lawn: slabs whose top is 2 mm above it (deep below it, see
  // kGroundSlabDepth) that do not collide (a slab edge would stop a wheel); the simulator finds the
  // surface under a wheel from the garden's paths.
  void Paths() {
    for (size_t i = 0; i < garden_.paths.size(); ++i) {
      const auto& path = garden_.paths[i];
      const garden::Material material = garden::GroundMaterial(path.surface);
      const std::string name = "garden/path" + std::to_string(i) + "_" + garden::ToString(path.surface);
      garden::GardenObject slab;
      slab.position = path.centre;
      slab.yaw = path.yaw;
      slab.base_height = 0.002 - garden::kGroundSlabDepth;
      Mesh(name, garden::BoxMesh({path.size.x(), path.size.y(), garden::kGroundSlabDepth}, garden::TileSize(material)),
           garden::ObjectPose(slab), garden::ToString(material), "garden_surface");
      labels_.push_back({name, ObjectClass::kGround, garden::kGroundObjectId, true, path.surface});
    }
  }

  void Objects() {
    for (const auto& object : garden_.objects) {
      const std::string name = "garden/" + std::to_string(object.id) + "_" + garden::ToString(object.object_class);
      const bool cuttable = std::find(options_.cuttable_objects.begin(), options_.cuttable_objects.end(), object.id) !=
                            options_.cuttable_objects.end();
      Mesh(name, garden::ObjectMesh(object, garden_.appearance_seed, options_.conditions.growth),
           garden::ObjectPose(object), garden::ToString(garden::MaterialOf(object.object_class)),
           cuttable ? "garden_surface" : "garden");
      labels_.push_back({name, object.object_class, static_cast<std::uint16_t>(object.id), false, garden_.ground});
      if (cuttable) Wood(object, name + "_wood");
    }
  }

  // A trimmed topiary's wood: its target shape kWoodDepth inside, collided with and not drawn.
  void Wood(const garden::GardenObject& object, const std::string& name) {
    const garden::Superellipsoid target = garden::TargetShape(object);
    garden::Mesh mesh;
    constexpr int kRings = 12, kSegments = 24;
    for (int r = 0; r <= kRings; ++r) {
      for (int s = 0; s < kSegments; ++s) {
        const double polar = M_PI * r / kRings, azimuth = 2.0 * M_PI * s / kSegments;
        const Eigen::Vector3d d(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
                                std::cos(polar));
        mesh.vertices.push_back(d * std::max(0.01, target.Radius(d) - kWoodDepth) +
                                Eigen::Vector3d(0, 0, target.half.z()));
        if (r == 0 || r == kRings) break;  // one vertex at each pole
      }
    }
    // Only the convex hull collides: the vertices are enough (group 3: not drawn).
    Mesh(name, mesh, garden::ObjectPose(object), garden::ToString(garden::MaterialOf(object.object_class)), "garden",
         " group=\"3\"");
    labels_.push_back({name, object.object_class, static_cast<std::uint16_t>(object.id), false, garden_.ground});
  }

  const garden::Garden& garden_;
  const WorldOptions& options_;
  std::ostringstream assets_, geoms_;
  std::vector<GeomLabel> labels_;
};

// The sun: a directional light from (azimuth, elevation) of the run's conditions; the sky fills.
std::string Lights(const garden::Sun& sun) {
  const Eigen::Vector3d towards_sun(std::cos(sun.elevation) * std::cos(sun.azimuth),
                                    std::cos(sun.elevation) * std::sin(sun.azimuth), std::sin(sun.elevation));
  const Eigen::Vector3d sun_colour = sun.colour * sun.intensity;
  std::ostringstream xml;
  xml << "    <light name=\"sun\" directional=\"true\" castshadow=\"" << (sun.shadows ? "true" : "false") << "\" pos=\""
      << Vec(towards_sun * 20.0) << "\" dir=\"" << Vec(-towards_sun) << "\" diffuse=\"" << Vec(sun_colour)
      << "\" specular=\"0.1 0.1 0.1\"/>\n"
      << "    <light name=\"sky\" directional=\"true\" castshadow=\"false\" pos=\"0 0 20\" dir=\"0 0 -1\" "
         "diffuse=\"0.15 0.16 0.18\" ambient=\""
      << Vec(sun.ambient) << "\" specular=\"0 0 0\"/>\n";
  return xml.str();
}

// The view: the offscreen buffer fits the largest camera render, shadows cover the garden.
std::string StatisticAndVisual(const garden::Garden& garden, const robot::CameraRig& rig, const WorldOptions& options) {
  int max_render_w = 0, max_render_h = 0;
  for (const auto& cam : rig.cameras()) {
    const RenderPinhole render = RenderPinholeFor(cam.intrinsics, options.render_oversampling);
    max_render_w = std::max(max_render_w, render.width);
    max_render_h = std::max(max_render_h, render.height);
  }
  const double shadow_extent = garden.size.norm() / 2.0 + 5.0;
  std::ostringstream xml;
  // extent 1 makes znear/zfar/shadowclip read in metres.
  xml << "  <statistic center=\"" << Num(garden.centre.x()) << " " << Num(garden.centre.y()) << " 0\" extent=\"1\"/>\n"
      << "  <visual>\n"
      << "    <global offwidth=\"" << max_render_w << "\" offheight=\"" << max_render_h << "\"/>\n"
      << "    <quality shadowsize=\"2048\" offsamples=\"" << options.msaa_samples << "\"/>\n"
      << "    <map znear=\"0.02\" zfar=\"80\" shadowclip=\"" << Num(shadow_extent) << "\"/>\n"
      << "    <headlight active=\"0\" ambient=\"0 0 0\" diffuse=\"0 0 0\" specular=\"0 0 0\"/>\n"
      << "  </visual>\n";
  return xml.str();
}

}  // namespace

std::string DefaultTextureCacheDir() {
  if (const char* dir = std::getenv("TRIMBOT_TEXTURE_CACHE")) return dir;
  std::error_code error;
  const fs::path temp = fs::temp_directory_path(error);
  return error ? std::string() : (temp / "trimbot_texture_cache").string();
}

WorldSpec ComposeWorld(const robot::RobotDescription& robot, const robot::CameraRig& rig, const garden::Garden& garden,
                       const WorldOptions& options, const std::string& output_dir) {
  const fs::path dir = fs::path(output_dir);
  const fs::path texture_dir = dir / "textures";
  fs::create_directories(texture_dir);

  WorldSpec spec;
  const RobotMjcf robot_mjcf = ComposeRobot(robot, rig, {options.start, options.render_oversampling});
  spec.labels = robot_mjcf.labels;
  for (const auto& cam : rig.cameras()) spec.camera_names.push_back(cam.name);
  const GardenEmitter garden_mjcf(garden, options, TextureAssets(garden, options, texture_dir));
  spec.labels.insert(spec.labels.end(), garden_mjcf.labels().begin(), garden_mjcf.labels().end());

  std::ostringstream xml;
  xml << "<mujoco model=\"trimbot_in_" << garden.name << "\">\n"
      << "  <!-- Composed by sim/world_builder from " << garden.source << ", with the robot (" << kRobotFile
      << ") from " << robot.path() << " and " << rig.source() << ". -->\n"
      << "  <include file=\"" << kRobotFile << "\"/>\n"
      << "  <option timestep=\"" << Num(options.timestep) << "\"/>\n"  // the integrator is the robot's
      << StatisticAndVisual(garden, rig, options)
      // The garden collides with the robot (contype bits: 1 garden, 2 robot; see robot_mjcf).
      << "  <default>\n"
      << "    <default class=\"garden\"><geom contype=\"1\" conaffinity=\"2\" group=\"0\"/></default>\n"
      << "    <default class=\"garden_surface\"><geom contype=\"0\" conaffinity=\"0\" group=\"0\"/></default>\n"
      << "  </default>\n"
      << "  <asset>\n"
      << garden_mjcf.assets() << "  </asset>\n"
      << "  <worldbody>\n"
      << Lights(garden::SunFor(garden, options.conditions)) << garden_mjcf.geoms() << "  </worldbody>\n"
      << "</mujoco>\n";

  WriteFileAtomically((dir / kRobotFile).string(), robot_mjcf.xml);
  spec.mjcf_path = fs::absolute(dir / "world.xml").string();
  WriteFileAtomically(spec.mjcf_path, xml.str());
  return spec;
}

}  // namespace trimbot::sim
