#pragma once
// Offscreen rendering of the ring cameras with OSMesa (software OpenGL: no display, no GPU).
// Each camera is rendered as a wide ideal pinhole and resampled into its calibrated model
// (intrinsics and radtan distortion). Besides the colour image it can produce the ground truth:
// metric depth along the optical axis and per-pixel class and object labels.
#include <opencv2/core.hpp>

#include <memory>
#include <vector>

#include "trimbot/robot/camera_rig.h"
#include "trimbot/sim/render_pinhole.h"
#include "trimbot/sim/rendered_view.h"
#include "trimbot/sim/world.h"

namespace trimbot::sim {

class RingRenderer {
 public:
  // `resolution_scale` renders images at a fraction of the calibrated resolution (0.5 = half).
  RingRenderer(const World& world, const robot::CameraRig& rig, double resolution_scale = 1.0,
               double oversampling = 1.0);
  ~RingRenderer();
  RingRenderer(const RingRenderer&) = delete;
  RingRenderer& operator=(const RingRenderer&) = delete;

  // Renders rig camera `index` in the world's current state (call mj_forward first).
  RenderedView Render(int index, bool with_ground_truth);
  // The camera model the images follow (the calibration, scaled by resolution_scale).
  const robot::PinholeRadtan& camera_model(int index) const { return cameras_.at(static_cast<size_t>(index)).model; }

 private:
  struct CameraSetup {
    robot::PinholeRadtan model;
    RenderPinhole render;
    cv::Mat map_x, map_y;  // output pixel -> render pixel
  };
  void RenderPass(const CameraSetup& camera, int camera_id, bool segmentation, cv::Mat* rgb, cv::Mat* depth);

  const World& world_;
  std::vector<CameraSetup> cameras_;
  struct GlState;
  std::unique_ptr<GlState> gl_;
};

}  // namespace trimbot::sim
