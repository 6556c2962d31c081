#include "trimbot/sim/ring_renderer.h"

#include <GL/osmesa.h>

#include <opencv2/imgproc.hpp>
#include <chrono>
#include <cmath>
#include <stdexcept>

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

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

RingRenderer::RingRenderer(const World& world, const robot::CameraRig& rig, double oversampling)
    : world_(world), rig_(rig), oversampling_(oversampling), gl_(std::make_unique<GlState>()) {
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
      setup.map_y.at<float>(v, u) = static_cast<float>(setup.render.focal * ray.y() + setup.render.cy);
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
  gl_->scene.flags[mjRND_SEGMENT] = segmentation ? 1 : 0;
  gl_->scene.flags[mjRND_IDCOLOR] = segmentation ? 1 : 0;
  const mjrRect viewport = {0, 0, camera.render.width, camera.render.height};
  mjr_render(viewport, &gl_->scene, &gl_->render_context);
  glFinish();  // llvmpipe draws asynchronously: wait here so the draw is timed as drawing
  if (!segmentation) timings_.draw += SecondsSince(start);
  start = Clock::now();
  mjr_readPixels(gl_->rgb.data(), depth ? gl_->depth.data() : nullptr, viewport, &gl_->render_context);
  // OpenGL rows start at the bottom.
  const cv::Mat rgb_up(camera.render.height, camera.render.width, CV_8UC3, gl_->rgb.data());
  cv::flip(rgb_up, *rgb, 0);
  if (!segmentation) timings_.readback += SecondsSince(start);
  if (depth != nullptr) {
    const auto depth_start = Clock::now();
    const cv::Mat depth_up(camera.render.height, camera.render.width, CV_32F, gl_->depth.data());
    cv::Mat buffer;
    cv::flip(depth_up, buffer, 0);
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
    timings_.ground_truth += SecondsSince(depth_start);
  }
}

RenderedView RingRenderer::Render(int index, double resolution_scale, bool with_ground_truth) {
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
  RenderPass(camera, camera_id, false, &rgb, with_ground_truth ? &depth : nullptr);
  auto start = Clock::now();
  cv::remap(rgb, view.rgb, camera.map_x, camera.map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  timings_.distortion += SecondsSince(start);
  ++timings_.images;
  if (!with_ground_truth) return view;

  start = Clock::now();

  cv::remap(depth, view.depth, camera.map_x, camera.map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  cv::Mat segmentation;
  RenderPass(camera, camera_id, true, &segmentation, nullptr);
  // Segment colour = scene geom index + 1; map it to the model geom and its label.
  cv::Mat object_class(segmentation.size(), CV_8U, cv::Scalar(0));
  cv::Mat object_id(segmentation.size(), CV_16U, cv::Scalar(0));
  const mjvScene& scene = gl_->scene;
  for (int r = 0; r < segmentation.rows; ++r) {
    const cv::Vec3b* in = segmentation.ptr<cv::Vec3b>(r);
    for (int c = 0; c < segmentation.cols; ++c) {
      const int segment = in[c][0] + 256 * in[c][1] + 65536 * in[c][2] - 1;
      if (segment < 0 || segment >= scene.ngeom) continue;
      const mjvGeom& geom = scene.geoms[segment];
      if (geom.objtype != mjOBJ_GEOM) continue;
      const GeomLabel* label = world_.label(geom.objid);
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

}  // namespace trimbot::sim
