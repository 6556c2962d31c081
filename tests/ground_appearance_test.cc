// The rendered ground gives SIFT something to find (the visual localization's features). In its own
// executable, not camera_render_test: under the sanitizers OpenCV's SIFT over the four grounds takes
// 2 min, so CI runs it in the plain build only (camera_render_test is one of the sanitized tests).
#include <gtest/gtest.h>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdio>

#include "sim_test_support.h"

namespace trimbot::sim {
namespace {

using testing::TestConfig;

// Real features for localization: SIFT finds a few hundred keypoints in a ring image of each kind
// of ground (measured on the rendered, distorted, noisy image), whatever the garden's seed: the
// minimum over three appearance seeds is asserted. In sunlight: under a cloud the relief shading
// of the ground fades and SIFT finds fewer (123-209 on three of the four grounds when this run's
// first frame fell in a cloud's shadow).
TEST(GroundAppearance, SiftFindsFeaturesOnEveryGroundType) {
  for (const char* surface : {"grass", "gravel", "pavement", "soil"}) {
    std::size_t fewest = SIZE_MAX;
    for (const int seed : {-1, 1, 2, 3}) {  // -1: no seed in the file (derived from the name)
      const std::string seed_line = seed < 0 ? "" : "seed: " + std::to_string(seed) + "\n";
      const std::string garden = testing::WriteTempFile(std::string("ground_") + surface + ".yaml",
                                                        std::string("name: ground_") + surface + "\n" + seed_line +
                                                            "size: [30, 30]\nground: " + surface + "\nobjects: []\n");
      SimulatorConfig config = TestConfig(garden, std::string("sift_") + surface, true);
      config.conditions.clouds.cover = 0.0;
      Simulator simulator(config);
      const RingCapture capture = simulator.CaptureRing(false);
      const auto& image = capture.frame.images[0];
      const cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.data.data()));
      cv::Mat grey;
      cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
      std::vector<cv::KeyPoint> keypoints;
      cv::SIFT::create()->detect(grey, keypoints);
      // Only the ground half of the image has texture (the upper half is sky).
      std::printf("SIFT: %zu keypoints on %s, garden seed %d (cam0, 752x480)\n", keypoints.size(), surface, seed);
      fewest = std::min(fewest, keypoints.size());
    }
    // 250: the plainest ground, pavement, gives 278-307 (measured once the ground stopped
    // shadowing itself; its stripes had added features of their own).
    EXPECT_GE(fewest, 250u) << surface;
  }
}

}  // namespace
}  // namespace trimbot::sim
