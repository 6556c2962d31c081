#include "trimbot/sim/render_pinhole.h"

#include <algorithm>
#include <cmath>

namespace trimbot::sim {

RenderPinhole RenderPinholeFor(const robot::PinholeRadtan& camera, double oversampling) {
  // Walk the image border (pixel edges, not centres) and find the widest undistorted ray.
  double max_x = 0.0, max_y = 0.0;
  const double w = camera.width, h = camera.height;
  constexpr int kSamples = 64;
  for (int i = 0; i <= kSamples; ++i) {
    const double s = static_cast<double>(i) / kSamples;
    for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(-0.5 + s * w, -0.5), Eigen::Vector2d(-0.5 + s * w, h - 0.5),
                                         Eigen::Vector2d(-0.5, -0.5 + s * h), Eigen::Vector2d(w - 0.5, -0.5 + s * h)}) {
      const Eigen::Vector2d ray = camera.Undistort(pixel);
      max_x = std::max(max_x, std::abs(ray.x()));
      max_y = std::max(max_y, std::abs(ray.y()));
    }
  }
  RenderPinhole out;
  out.focal = std::max(camera.fx, camera.fy) * oversampling;
  // One pixel of margin so bilinear sampling never reads outside the render.
  out.width = 2 * static_cast<int>(std::ceil(max_x * out.focal + 1.0));
  out.height = 2 * static_cast<int>(std::ceil(max_y * out.focal + 1.0));
  out.cx = (out.width - 1) / 2.0;
  out.cy = (out.height - 1) / 2.0;
  out.fovy_degrees = 2.0 * std::atan(0.5 * out.height / out.focal) * 180.0 / M_PI;
  return out;
}

robot::PinholeRadtan Scaled(const robot::PinholeRadtan& camera, double scale) {
  robot::PinholeRadtan out = camera;
  out.width = static_cast<int>(std::lround(camera.width * scale));
  out.height = static_cast<int>(std::lround(camera.height * scale));
  out.fx = camera.fx * scale;
  out.fy = camera.fy * scale;
  // Pixel centres: (c + 0.5) scales with the image.
  out.cx = (camera.cx + 0.5) * scale - 0.5;
  out.cy = (camera.cy + 0.5) * scale - 0.5;
  return out;
}

}  // namespace trimbot::sim
