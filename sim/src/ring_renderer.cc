#include "trimbot/sim/ring_renderer.h"

#include <GL/osmesa.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "trimbot/common/wall_clock.h"

namespace trimbot::sim {

struct RingRenderer::GlState {
  OSMesaContext context = nullptr;
  std::vector<unsigned char> buffer;
  mjvScene scene;
  mjvOption option;
  mjrContext render_context;
  std::vector<unsigned char> rgb;
  std::vector<float> depth;
};

namespace {

using Clock = std::chrono::steady_clock;

using Vec3 = Eigen::Vector3d;

Vec3 ToVec(const float* v) { return Vec3(v[0], v[1], v[2]); }

// A half-space bounding the view volume: a point x is outside where normal.dot(x) > offset.
struct Plane {
  Vec3 normal;
  double offset;
  double Distance(const Vec3& x) const { return normal.dot(x) - offset; }
};

// The six planes of the camera's view volume, as OpenGL will draw it for this viewport.
std::array<Plane, 6> ViewVolume(const mjvGLCamera& camera, double aspect) {
  const Vec3 eye = ToVec(camera.pos), forward = ToVec(camera.forward).normalized();
  const Vec3 up = ToVec(camera.up).normalized(), right = forward.cross(up);
  const double near = camera.frustum_near;
  const double half_width = 0.5 * aspect * (camera.frustum_top - camera.frustum_bottom);
  const double left = (camera.frustum_center - half_width) / near,
               rightmost = (camera.frustum_center + half_width) / near;
  const double bottom = camera.frustum_bottom / near, top = camera.frustum_top / near;
  auto side = [&](const Vec3& axis, double slope, double sign) {
    // Points with sign * (axis . (x - eye) - slope * forward . (x - eye)) > 0 are outside.
    const Vec3 normal = (sign * (axis - slope * forward)).normalized();
    return Plane{normal, normal.dot(eye)};
  };
  return {side(right, rightmost, 1.0),
          side(right, left, -1.0),
          side(up, top, 1.0),
          side(up, bottom, -1.0),
          Plane{-forward, -forward.dot(eye) - near},
          Plane{forward, forward.dot(eye) + camera.frustum_far}};
}

// Keeps in the scene only the geoms that can show in this camera: those whose bounding sphere,
// or the shadow it casts from a shadow-casting directional light down to the ground, meets the
// view volume. What is dropped would be clipped by OpenGL anyway, so the image is the same; the
// three passes of a shadowed scene (lit, shadow map, shadowed) then draw about half the garden.
// Returns how many were dropped.
int KeepVisibleGeoms(mjvScene* scene, double aspect, const std::vector<double>& margins) {
  // MuJoCo keeps two eyes ipd apart; a mono render draws from their average.
  const mjvGLCamera camera = mjv_averageCamera(&scene->camera[0], &scene->camera[1]);
  const std::array<Plane, 6> volume = ViewVolume(camera, aspect);
  std::vector<Vec3> shadow_directions;
  if (scene->flags[mjRND_SHADOW]) {
    for (int i = 0; i < scene->nlight; ++i) {
      const mjvLight& light = scene->lights[i];
      if (!light.castshadow) continue;
      if (!light.directional) return 0;  // a point or spot light's shadows are not swept: draw all
      shadow_directions.push_back(ToVec(light.dir).normalized());
    }
  }
  const double longest_shadow = camera.frustum_far;
  auto capsule_outside = [&](const Vec3& a, const Vec3& b, double radius) {
    for (const Plane& plane : volume) {
      if (plane.Distance(a) > radius && plane.Distance(b) > radius) return true;
    }
    return false;
  };
  int kept = 0;
  for (int i = 0; i < scene->ngeom; ++i) {
    const mjvGeom& geom = scene->geoms[i];
    bool visible = geom.modelrbound <= 0.0;  // decor and unbounded geoms are always drawn
    const bool has_margin =
        geom.objtype == mjOBJ_GEOM && geom.objid >= 0 && geom.objid < static_cast<int>(margins.size());
    const double radius = geom.modelrbound + (has_margin ? margins[static_cast<std::size_t>(geom.objid)] : 0.0);
    const Vec3 centre = ToVec(geom.pos);
    if (!visible) visible = !capsule_outside(centre, centre, radius);
    for (size_t l = 0; !visible && l < shadow_directions.size(); ++l) {
      const Vec3& direction = shadow_directions[l];
      // The shadow falls along the light until the ground (z = 0).
      const double length =
          direction.z() < -1e-3 ? std::min((centre.z() + radius) / -direction.z(), longest_shadow) : longest_shadow;
      visible = !capsule_outside(centre, centre + std::max(length, 0.0) * direction, radius);
    }
    if (visible) scene->geoms[kept++] = geom;
  }
  const int dropped = scene->ngeom - kept;
  scene->ngeom = kept;
  return dropped;
}

}  // namespace

RingRenderer::RingRenderer(const World& world, const robot::CameraRig& rig, bool frustum_culling, double oversampling)
    : world_(world),
      rig_(rig),
      frustum_culling_(frustum_culling),
      oversampling_(oversampling),
      gl_(std::make_unique<GlState>()) {
  const mjModel* m = world.model();
  const int width = m->vis.global.offwidth, height = m->vis.global.offheight;
  gl_->context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 8, nullptr);
  if (gl_->context == nullptr) throw std::runtime_error("OSMesa: cannot create an OpenGL context");
  gl_->buffer.resize(static_cast<size_t>(width) * height * 4);
  if (!OSMesaMakeCurrent(gl_->context, gl_->buffer.data(), GL_UNSIGNED_BYTE, width, height)) {
    OSMesaDestroyContext(gl_->context);
    throw std::runtime_error("OSMesa: cannot make the context current");
  }
  mjv_defaultScene(&gl_->scene);
  mjv_defaultOption(&gl_->option);
  mjr_defaultContext(&gl_->render_context);
  mjv_makeScene(m, &gl_->scene, 2000);
  mjr_makeContext(m, &gl_->render_context, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &gl_->render_context);
  for (int g = 0; g < mjNGROUP; ++g) gl_->option.sitegroup[g] = 0;
  gl_->option.geomgroup[3] = 0;  // collision geometry is not drawn
  gl_->rgb.resize(static_cast<size_t>(width) * height * 3);
  gl_->depth.resize(static_cast<size_t>(width) * height);
  sun_light_ = mj_name2id(m, mjOBJ_LIGHT, "sun");
  if (sun_light_ >= 0) {
    for (int i = 0; i < 3; ++i) {
      sun_diffuse_[i] = m->light_diffuse[3 * sun_light_ + i];
      sun_specular_[i] = m->light_specular[3 * sun_light_ + i];
    }
  }
}

void RingRenderer::SetSunTransmittance(double transmittance) {
  if (sun_light_ < 0) return;
  // The model's light is read by mjv_updateScene for each draw; physics does not use it.
  mjModel* m = world_.model();
  for (int i = 0; i < 3; ++i) {
    m->light_diffuse[3 * sun_light_ + i] = static_cast<float>(sun_diffuse_[i] * transmittance);
    m->light_specular[3 * sun_light_ + i] = static_cast<float>(sun_specular_[i] * transmittance);
  }
}

void RingRenderer::ReplaceMeshVertices(int mesh_id, const std::vector<float>& vertices) {
  mjModel* m = world_.model();
  if (mesh_id < 0 || mesh_id >= m->nmesh || static_cast<int>(vertices.size()) != 3 * m->mesh_vertnum[mesh_id]) {
    throw std::invalid_argument("RingRenderer::ReplaceMeshVertices: not the mesh's vertex count");
  }
  const mjModel* mc = m;
  if (OSMesaGetCurrentContext() != gl_->context &&
      !OSMesaMakeCurrent(gl_->context, gl_->buffer.data(), GL_UNSIGNED_BYTE, mc->vis.global.offwidth,
                         mc->vis.global.offheight)) {
    throw std::runtime_error("OSMesa: cannot make the context current");
  }
  // mjr_uploadMesh reads the model's vertices: swap the drawn ones in for the upload, then back,
  // so collisions keep the mesh as built.
  float* stored = m->mesh_vert + 3 * m->mesh_vertadr[mesh_id];
  std::vector<float> kept(stored, stored + vertices.size());
  std::copy(vertices.begin(), vertices.end(), stored);
  mjr_uploadMesh(m, &gl_->render_context, mesh_id);
  std::copy(kept.begin(), kept.end(), stored);
}

RingRenderer::~RingRenderer() {
  mjr_freeContext(&gl_->render_context);
  mjv_freeScene(&gl_->scene);
  OSMesaDestroyContext(gl_->context);
}

const RingRenderer::CameraSetup& RingRenderer::Setup(int index, double resolution_scale) {
  if (index < 0 || index >= rig_.size()) throw std::out_of_range("RingRenderer: no camera " + std::to_string(index));
  if (!(resolution_scale > 0.0 && resolution_scale <= 1.0)) {
    throw std::invalid_argument("RingRenderer: resolution scale must be in (0, 1]");
  }
  const std::pair<int, long> key(index, std::lround(resolution_scale * 10000.0));
  auto found = setups_.find(key);
  if (found != setups_.end()) return found->second;
  const robot::PinholeRadtan& calibration = rig_.camera(index).intrinsics;
  CameraSetup setup;
  setup.model = Scaled(calibration, resolution_scale);
  // The MJCF camera's fovy was set for the full-resolution render; keep the angle, scale pixels.
  const RenderPinhole full = RenderPinholeFor(calibration, oversampling_);
  setup.render = full;
  setup.render.width = static_cast<int>(std::lround(full.width * resolution_scale / 2.0)) * 2;
  setup.render.height = static_cast<int>(std::lround(full.height * resolution_scale / 2.0)) * 2;
  setup.render.focal = 0.5 * setup.render.height / std::tan(0.5 * full.fovy_degrees * M_PI / 180.0);
  setup.render.cx = (setup.render.width - 1) / 2.0;
  setup.render.cy = (setup.render.height - 1) / 2.0;
  const mjModel* m = world_.model();
  if (setup.render.width > m->vis.global.offwidth || setup.render.height > m->vis.global.offheight) {
    throw std::runtime_error("render size exceeds the world's offscreen buffer");
  }
  setup.map_x.create(setup.model.height, setup.model.width, CV_32F);
  setup.map_y.create(setup.model.height, setup.model.width, CV_32F);
  for (int v = 0; v < setup.model.height; ++v) {
    for (int u = 0; u < setup.model.width; ++u) {
      const Eigen::Vector2d ray = setup.model.Undistort(Eigen::Vector2d(u, v));
      setup.map_x.at<float>(v, u) = static_cast<float>(setup.render.focal * ray.x() + setup.render.cx);
      // OpenGL rows start at the bottom: the map reads the render upside down, so no flip is needed.
      const double row = setup.render.focal * ray.y() + setup.render.cy;
      setup.map_y.at<float>(v, u) = static_cast<float>(setup.render.height - 1 - row);
    }
  }
  return setups_.emplace(key, std::move(setup)).first->second;
}

void RingRenderer::RenderPass(const CameraSetup& camera, int camera_id, bool segmentation, cv::Mat* rgb,
                              cv::Mat* depth) {
  const mjModel* m = world_.model();
  auto start = Clock::now();
  mjvCamera view;
  mjv_defaultCamera(&view);
  view.type = mjCAMERA_FIXED;
  view.fixedcamid = camera_id;
  mjv_updateScene(m, world_.data(), &gl_->option, nullptr, &view, mjCAT_ALL, &gl_->scene);
  const int culled =
      frustum_culling_ ? KeepVisibleGeoms(&gl_->scene, static_cast<double>(camera.render.width) / camera.render.height,
                                          culling_margins_)
                       : 0;
  if (!segmentation) {
    timings_.geoms_in_view += gl_->scene.ngeom;
    timings_.geoms_culled += culled;
  }
  gl_->scene.flags[mjRND_SEGMENT] = segmentation ? 1 : 0;
  gl_->scene.flags[mjRND_IDCOLOR] = segmentation ? 1 : 0;
  const mjrRect viewport = {0, 0, camera.render.width, camera.render.height};
  mjr_render(viewport, &gl_->scene, &gl_->render_context);
  glFinish();  // llvmpipe draws asynchronously: wait here so the draw is timed as drawing
  if (!segmentation) timings_.draw += SecondsSince(start);
  start = Clock::now();
  mjr_readPixels(gl_->rgb.data(), depth ? gl_->depth.data() : nullptr, viewport, &gl_->render_context);
  // Rows stay in OpenGL's order (bottom first): the camera's maps turn them upright. The image
  // shares the renderer's buffer, valid until the next pass.
  *rgb = cv::Mat(camera.render.height, camera.render.width, CV_8UC3, gl_->rgb.data());
  if (!segmentation) timings_.readback += SecondsSince(start);
  if (depth != nullptr) {
    const auto depth_start = Clock::now();
    const cv::Mat buffer(camera.render.height, camera.render.width, CV_32F, gl_->depth.data());
    // Non-linear depth buffer -> metres along the optical axis (standard OpenGL projection).
    const double znear = m->vis.map.znear * m->stat.extent;
    const double zfar = m->vis.map.zfar * m->stat.extent;
    depth->create(buffer.size(), CV_32F);
    for (int r = 0; r < buffer.rows; ++r) {
      const float* in = buffer.ptr<float>(r);
      float* out = depth->ptr<float>(r);
      for (int c = 0; c < buffer.cols; ++c) {
        out[c] = in[c] >= 1.0f ? 0.0f : static_cast<float>(znear / (1.0 - in[c] * (1.0 - znear / zfar)));
      }
    }
    timings_.depth += SecondsSince(depth_start);
  }
}

RenderedView RingRenderer::Render(int index, double resolution_scale, bool with_ground_truth, bool with_depth) {
  const CameraSetup& camera = Setup(index, resolution_scale);
  // Several renderers (simulators) may live in one process; each draws with its own context.
  const mjModel* m = world_.model();
  if (OSMesaGetCurrentContext() != gl_->context &&
      !OSMesaMakeCurrent(gl_->context, gl_->buffer.data(), GL_UNSIGNED_BYTE, m->vis.global.offwidth,
                         m->vis.global.offheight)) {
    throw std::runtime_error("OSMesa: cannot make the context current");
  }
  const int camera_id = world_.camera_id(index);
  RenderedView view;
  cv::Mat rgb, depth;
  RenderPass(camera, camera_id, false, &rgb, with_ground_truth || with_depth ? &depth : nullptr);
  auto start = Clock::now();
  cv::remap(rgb, view.rgb, camera.map_x, camera.map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  timings_.distortion += SecondsSince(start);
  ++timings_.images;
  if (!depth.empty()) {
    start = Clock::now();
    cv::remap(depth, view.depth, camera.map_x, camera.map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
    timings_.depth += SecondsSince(start);
  }
  if (!with_ground_truth) return view;

  start = Clock::now();

  cv::Mat segmentation;
  RenderPass(camera, camera_id, true, &segmentation, nullptr);
  // Segment colour = the geom's segmentation id + 1 (its index in the scene before culling); map it
  // to the model geom and its label.
  const mjvScene& scene = gl_->scene;
  std::vector<const GeomLabel*> label_of_segment;
  for (int i = 0; i < scene.ngeom; ++i) {
    const mjvGeom& geom = scene.geoms[i];
    if (geom.segid < 0 || geom.objtype != mjOBJ_GEOM) continue;
    if (geom.segid >= static_cast<int>(label_of_segment.size())) label_of_segment.resize(geom.segid + 1, nullptr);
    label_of_segment[geom.segid] = world_.label(geom.objid);
  }
  cv::Mat object_class(segmentation.size(), CV_8U, cv::Scalar(0));
  cv::Mat object_id(segmentation.size(), CV_16U, cv::Scalar(0));
  for (int r = 0; r < segmentation.rows; ++r) {
    const cv::Vec3b* in = segmentation.ptr<cv::Vec3b>(r);
    for (int c = 0; c < segmentation.cols; ++c) {
      const int segment = in[c][0] + 256 * in[c][1] + 65536 * in[c][2] - 1;
      if (segment < 0 || segment >= static_cast<int>(label_of_segment.size())) continue;
      const GeomLabel* label = label_of_segment[segment];
      if (label == nullptr) continue;
      object_class.at<uchar>(r, c) = static_cast<uchar>(label->object_class);
      object_id.at<uint16_t>(r, c) = label->object_id;
    }
  }
  cv::remap(object_class, view.object_class, camera.map_x, camera.map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  cv::remap(object_id, view.object_id, camera.map_x, camera.map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  // The skybox is drawn as far geometry; where nothing was hit, depth is "none" (0).
  view.depth.setTo(0.0f, view.object_class == 0);
  timings_.ground_truth += SecondsSince(start);
  return view;
}

cv::Mat RingRenderer::RenderExternalView(const Eigen::Vector3d& lookat, double distance, double azimuth,
                                         double elevation, int width, int height) {
  const mjModel* m = world_.model();
  width = std::min(width, m->vis.global.offwidth);
  height = std::min(height, m->vis.global.offheight);
  if (OSMesaGetCurrentContext() != gl_->context &&
      !OSMesaMakeCurrent(gl_->context, gl_->buffer.data(), GL_UNSIGNED_BYTE, m->vis.global.offwidth,
                         m->vis.global.offheight)) {
    throw std::runtime_error("OSMesa: cannot make the context current");
  }
  mjvCamera view;
  mjv_defaultCamera(&view);
  view.type = mjCAMERA_FREE;
  for (int i = 0; i < 3; ++i) view.lookat[i] = lookat[i];
  view.distance = distance;
  view.azimuth = azimuth;
  view.elevation = elevation;
  mjv_updateScene(m, world_.data(), &gl_->option, nullptr, &view, mjCAT_ALL, &gl_->scene);
  gl_->scene.flags[mjRND_SEGMENT] = 0;
  gl_->scene.flags[mjRND_IDCOLOR] = 0;
  const mjrRect viewport = {0, 0, width, height};
  mjr_render(viewport, &gl_->scene, &gl_->render_context);
  glFinish();
  mjr_readPixels(gl_->rgb.data(), nullptr, viewport, &gl_->render_context);
  cv::Mat rgb;
  cv::flip(cv::Mat(height, width, CV_8UC3, gl_->rgb.data()), rgb, 0);  // OpenGL rows start at the bottom
  return rgb;
}

}  // namespace trimbot::sim
