#pragma once
// Offscreen rendering of the ring cameras with OSMesa (software OpenGL: no display, no GPU).
// Each camera is rendered as a wide ideal pinhole and resampled into its calibrated model
// (intrinsics and radtan distortion) by a remap precomputed per camera and resolution. Besides
// the colour image it can produce the ground truth: metric depth along the optical axis and
// per-pixel class and object labels.
#include <opencv2/core.hpp>

#include <array>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "trimbot/robot/camera_rig.h"
#include "trimbot/sim/render_pinhole.h"
#include "trimbot/sim/rendered_view.h"
#include "trimbot/sim/world.h"

namespace trimbot::sim {

// Wall-clock seconds spent per rendering stage since the renderer was made.
struct RenderTimings {
  double draw = 0.0;          // OpenGL drawing (scene update, shadow map, rasterization)
  double readback = 0.0;      // the MSAA resolve, reading the pixels back, flipping them upright
  double distortion = 0.0;    // resampling the pinhole render into the calibrated (distorted) camera
  double depth = 0.0;         // depth to metres and its remap (ground truth, motion blur)
  double ground_truth = 0.0;  // the label pass and its remaps, when asked for
  long images = 0;            // camera images rendered
  long geoms_in_view = 0;     // summed over colour images: geoms drawn,
  long geoms_culled = 0;      // and geoms outside the view volume (and their shadows), not drawn
};

class RingRenderer {
 public:
  // frustum_culling: each camera draws only the geoms that can show in it (the same image, faster).
  RingRenderer(const World& world, const robot::CameraRig& rig, bool frustum_culling = true, double oversampling = 1.0);
  ~RingRenderer();
  RingRenderer(const RingRenderer&) = delete;
  RingRenderer& operator=(const RingRenderer&) = delete;

  // Renders rig camera `index` at `resolution_scale` of its calibrated size (0.5 = half) in the
  // world's current state (call mj_forward first). `with_depth`: the view's depth without the
  // label pass (for effects that need it, such as motion blur); ground truth includes it.
  RenderedView Render(int index, double resolution_scale, bool with_ground_truth, bool with_depth = false);
  // The calibrated model of camera `index` at `resolution_scale` (the rendered image's).
  const robot::PinholeRadtan& Model(int index, double resolution_scale) { return Setup(index, resolution_scale).model; }

  // Render-only changes of the scene (physics keeps its own geometry and light):
  // the sun's direct light as a fraction of the clear sky's (cloud shadows),
  void SetSunTransmittance(double transmittance);
  // a mesh's vertices (in its frame, as mjModel::mesh_vert) replaced for drawing (plants in the
  // wind); the margins (m, by geom id) widen each geom's view-volume test by the most it can move.
  void ReplaceMeshVertices(int mesh_id, const std::vector<float>& vertices);
  void SetCullingMargins(std::vector<double> margins) { culling_margins_ = std::move(margins); }
  const RenderTimings& timings() const { return timings_; }
  // A view from outside the robot (for reports): a free camera `distance` m from `lookat`, at
  // `azimuth` and `elevation` (deg, MuJoCo's convention), RGB, upright, at most the offscreen size.
  cv::Mat RenderExternalView(const Eigen::Vector3d& lookat, double distance, double azimuth, double elevation,
                             int width, int height);

 private:
  struct CameraSetup {
    robot::PinholeRadtan model;
    RenderPinhole render;
    cv::Mat map_x, map_y;  // output pixel -> render pixel (rows as OpenGL reads them: bottom first)
  };
  // Built on the first request for a camera and resolution, then kept.
  const CameraSetup& Setup(int index, double resolution_scale);
  void RenderPass(const CameraSetup& camera, int camera_id, bool segmentation, cv::Mat* rgb, cv::Mat* depth);

  const World& world_;
  const robot::CameraRig& rig_;
  bool frustum_culling_;
  double oversampling_;
  std::vector<double> culling_margins_;  // by geom id (empty: none)
  int sun_light_ = -1;
  std::array<float, 3> sun_diffuse_{}, sun_specular_{};
  std::map<std::pair<int, long>, CameraSetup> setups_;  // (camera, scale in 1/10000)
  RenderTimings timings_;
  struct GlState;
  std::unique_ptr<GlState> gl_;
};

}  // namespace trimbot::sim
