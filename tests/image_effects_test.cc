// The image effects with physical causes (sim/motion_blur.h, sim/weather.h): motion blur as long
// as the exposure times the image speed, plants that move in the wind while trunks stand, and
// wind and clouds that the seed reproduces.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>

#include "sim_test_support.h"
#include "trimbot/sim/motion_blur.h"
#include "trimbot/sim/weather.h"

namespace trimbot::sim {
namespace {

robot::PinholeRadtan Pinhole(int width, int height, double focal) {
  robot::PinholeRadtan camera;
  camera.width = width;
  camera.height = height;
  camera.fx = camera.fy = focal;
  camera.cx = (width - 1) / 2.0;
  camera.cy = (height - 1) / 2.0;
  return camera;
}

// Width (px) over which the middle row rises from 10 % to 90 % of a dark-to-bright step.
double EdgeWidth(const cv::Mat& rgb) {
  const int row = rgb.rows / 2;
  const double low = rgb.at<cv::Vec3b>(row, 0)[0], high = rgb.at<cv::Vec3b>(row, rgb.cols - 1)[0];
  const auto crossing = [&](double fraction) {
    const double level = low + fraction * (high - low);
    for (int c = 1; c < rgb.cols; ++c) {
      const double a = rgb.at<cv::Vec3b>(row, c - 1)[0], b = rgb.at<cv::Vec3b>(row, c)[0];
      if (a < level && b >= level) return c - 1 + (level - a) / (b - a);
    }
    return -1.0;
  };
  return crossing(0.9) - crossing(0.1);
}

cv::Mat VerticalEdge(int width, int height) {
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(40, 40, 40));
  image.colRange(width / 2, width).setTo(cv::Scalar(220, 220, 220));
  return image;
}

// A box blur of length L turns a step into a linear ramp: its 10-90 % width grows by 0.8 L. Panning at w rad/s
// moves the image centre by fx w t; driving sideways at v m/s past a wall Z m away by fx v t / Z.
TEST(MotionBlur, WidensAnEdgeByTheExposureTimesTheImageSpeed) {
  const robot::PinholeRadtan camera = Pinhole(200, 60, 500.0);
  MotionBlur blur;
  cv::Mat still = VerticalEdge(camera.width, camera.height);
  const double sharp = EdgeWidth(still);  // 0.8 px: between two pixels
  EXPECT_LT(sharp, 1.0);

  CameraTwist pan;
  pan.angular.y() = 1.0;  // rad/s
  cv::Mat panned = still.clone();
  const double length = blur.Apply(0, camera, cv::Mat(), pan, 0.010, &panned);          // 10 ms: 5 px at the centre
  EXPECT_NEAR(length, 500.0 * 1.0 * 0.010 * (1.0 + std::pow(100.0 / 500.0, 2)), 0.05);  // the corners' longest
  EXPECT_NEAR(EdgeWidth(panned) - sharp, 0.8 * 5.0, 0.25);

  CameraTwist sideways;
  sideways.linear.x() = 0.25;  // m/s
  const cv::Mat wall(camera.height, camera.width, CV_32F, cv::Scalar(0.5f));
  cv::Mat driven = still.clone();
  blur.Apply(0, camera, wall, sideways, 0.020, &driven);  // 500 * 0.25 * 0.02 / 0.5 = 5 px
  EXPECT_NEAR(EdgeWidth(driven) - sharp, 0.8 * 5.0, 0.25);

  // The same motion past a wall twice as far blurs half as much.
  const cv::Mat far_wall(camera.height, camera.width, CV_32F, cv::Scalar(1.0f));
  cv::Mat farther = still.clone();
  blur.Apply(0, camera, far_wall, sideways, 0.020, &farther);
  EXPECT_NEAR(EdgeWidth(farther) - sharp, 0.8 * 2.5, 0.25);

  // In sunlight (0.15 ms) a 0.5 rad/s turn blurs by 0.04 px: left out, the image untouched.
  cv::Mat sunlit = still.clone();
  CameraTwist turn;
  turn.angular.y() = 0.5;
  EXPECT_LT(blur.Apply(0, camera, cv::Mat(), turn, 1.5e-4, &sunlit), kNegligibleBlurPixels);
  EXPECT_EQ(cv::norm(sunlit, still, cv::NORM_INF), 0.0);
}

// The same seed gives the same gusts and cloud shadows, whatever was asked for before; another
// seed other ones. The gust signal has unit variance; the shaded share of time is the cover.
TEST(Weather, TheSeedReproducesTheWindAndTheClouds) {
  const garden::Conditions conditions;
  const GustyWind a(conditions.wind, 5), b(conditions.wind, 5), other(conditions.wind, 6);
  const Eigen::Vector2d here(1.0, 2.0);
  double sum = 0.0, sum2 = 0.0, differs = 0.0;
  const int samples = 40000;
  for (int i = 0; i < samples; ++i) {
    const double t = 0.5 * i;
    const double gust = a.Gust(here, t);
    ASSERT_EQ(gust, b.Gust(here, t));
    differs = std::max(differs, std::abs(gust - other.Gust(here, t)));
    sum += gust;
    sum2 += gust * gust;
  }
  EXPECT_GT(differs, 0.5);
  EXPECT_NEAR(sum / samples, 0.0, 0.1);
  EXPECT_NEAR(std::sqrt(sum2 / samples), 1.0, 0.1);

  const CloudShadows in_order(conditions.clouds, 9), backwards(conditions.clouds, 9), elsewhere(conditions.clouds, 10);
  EXPECT_GE(backwards.DirectTransmittance(5000.0), 0.0);  // drawn far ahead first
  double shaded = 0.0, changed = 0.0;
  const int steps = 200000;
  for (int i = 0; i < steps; ++i) {
    const double t = 0.5 * i;
    const double transmittance = in_order.DirectTransmittance(t);
    ASSERT_EQ(transmittance, backwards.DirectTransmittance(t));
    ASSERT_GE(transmittance, conditions.clouds.direct_transmittance);
    ASSERT_LE(transmittance, 1.0);
    changed = std::max(changed, std::abs(transmittance - elsewhere.DirectTransmittance(t)));
    shaded += transmittance < 0.5 ? 1.0 : 0.0;
  }
  EXPECT_GT(changed, 0.5);
  EXPECT_NEAR(shaded / steps, conditions.clouds.cover, 0.04);  // ~1000 spells over 28 h

  garden::Clouds clear = conditions.clouds;
  clear.cover = 0.0;
  EXPECT_EQ(CloudShadows(clear, 9).DirectTransmittance(100.0), 1.0);
}

// Two ring frames 0.2 s apart with the robot standing: the wind moves the tree's crown and the
// topiary (their depth changes), not the tree's trunk or the fence.
TEST(Weather, WindMovesABushsPixelsBetweenTwoFramesAndNotItsTrunk) {
  SimulatorConfig config = testing::TestConfig(testing::TestLawn(), "wind", true);
  config.cameras_on_schedule = false;
  config.resolution_scale = 0.5;
  config.conditions.clouds.cover = 0.0;
  Simulator simulator(config);
  SensorOutputs sensors;
  GroundTruth truth;
  for (int i = 0; i < 800; ++i) simulator.Step(&sensors, &truth);  // 2 s: the base settles on its wheels
  const RingCapture first = simulator.CaptureRing(true);
  for (int i = 0; i < 80; ++i) simulator.Step(&sensors, &truth);  // 0.2 s
  const RingCapture second = simulator.CaptureRing(true);

  // Per object id: pixels seen in both frames, and those whose depth changed by more than 1 mm.
  std::map<int, std::pair<int, int>> moved;
  for (std::size_t c = 0; c < first.truth.views.size(); ++c) {
    const RenderedView& a = first.truth.views[c];
    const RenderedView& b = second.truth.views[c];
    for (int r = 0; r < a.depth.rows; ++r) {
      for (int col = 0; col < a.depth.cols; ++col) {
        const int id = a.object_id.at<uint16_t>(r, col);
        if (id == 0 || id != b.object_id.at<uint16_t>(r, col)) continue;
        auto& [seen, changed] = moved[id];
        ++seen;
        if (std::abs(a.depth.at<float>(r, col) - b.depth.at<float>(r, col)) > 1e-3f) ++changed;
      }
    }
  }
  for (int plant : {1, 6}) {  // the topiary at (3, 1.2), the tree's crown
    ASSERT_GT(moved[plant].first, 200) << "object " << plant << " not in view";
    EXPECT_GT(moved[plant].second, 0.3 * moved[plant].first) << "object " << plant;
  }
  for (int still : {7, 8}) {  // the tree's trunk, the fence
    ASSERT_GT(moved[still].first, 200) << "object " << still << " not in view";
    EXPECT_EQ(moved[still].second, 0) << "object " << still;
  }
}

}  // namespace
}  // namespace trimbot::sim
