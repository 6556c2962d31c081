// Obstacles seen by stereo: the layer's marking, clearing and decay on synthetic observations, and
// on rendered frames a box in front of the robot marked where it stands and cleared once removed.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <vector>

#include "sim_test_support.h"
#include "trimbot/perception/obstacle_points.h"
#include "trimbot/perception/stereo.h"
#include "trimbot/stack/obstacle_layer.h"

namespace trimbot::stack {
namespace {

// An empty prior map, 14 x 12 m at 5 cm, origin (-5, -6).
OccupancyGrid EmptyMap() { return OccupancyGrid(cv::Mat::zeros(240, 280, CV_8U), 0.05, {-5.0, -6.0}); }

// Cells believed occupied within a rectangle (map frame).
int OccupiedIn(const ObstacleLayer& layer, const Eigen::Vector2d& low, const Eigen::Vector2d& high) {
  int count = 0;
  for (double x = low.x() + 0.025; x < high.x(); x += 0.05) {
    for (double y = low.y() + 0.025; y < high.y(); y += 0.05) count += layer.Occupied({x, y}) ? 1 : 0;
  }
  return count;
}

// A camera at the origin, 0.5 m up, sees a 0.4 m box at x = 2..2.4 and the ground before it.
ObstacleObservation SeeBox(double stamp, bool box_there) {
  ObstacleObservation o;
  o.stamp = stamp;
  o.min_obstacle_height = 0.1;
  ObstacleView view;
  view.sensor_height = 0.5;
  for (double y = -0.2; y <= 0.2; y += 0.02) {
    for (int k = 0; k < 4 && box_there; ++k) view.obstacles.emplace_back(2.0 + 0.01 * k, y);
    for (double x = 0.8; x <= (box_there ? 1.95 : 3.0); x += 0.02) view.ground.emplace_back(x, y);
  }
  o.views.push_back(view);
  return o;
}

TEST(ObstacleLayer, MarksWhatIsSeenClearsWhatIsSeenFreeAndForgets) {
  const OccupancyGrid map = EmptyMap();
  ObstacleLayerParameters parameters;
  ObstacleLayer layer(map, parameters);
  layer.Integrate(SeeBox(0.0, true));
  EXPECT_EQ(OccupiedIn(layer, {1.95, -0.25}, {2.1, 0.25}), 0) << "one frame is not enough (speckle)";
  layer.Integrate(SeeBox(0.4, true));
  EXPECT_GT(OccupiedIn(layer, {1.95, -0.25}, {2.1, 0.25}), 6);
  EXPECT_EQ(layer.OccupiedCells(), OccupiedIn(layer, {1.95, -0.25}, {2.1, 0.25})) << "nothing else";
  EXPECT_LT(layer.LogOdds({1.8, 0.0}), 0.0) << "the ground before the box was seen free";
  EXPECT_EQ(layer.LogOdds({0.5, 0.0}), 0.0) << "the rays pass too high there to tell";
  // The merged costmap holds the box: the prior map's cells with the layer's added.
  const OccupancyGrid merged = layer.MergedWith(map);
  EXPECT_LT(merged.DistanceToObstacle({2.025, 0.0}), 0.03);
  EXPECT_NEAR(merged.DistanceToObstacle({1.5, 0.0}), 0.5, 0.06);
  // The box is taken away: the ground where it stood is seen, the cells are cleared.
  for (int k = 0; k < 6; ++k) layer.Integrate(SeeBox(0.8 + 0.4 * k, false));
  EXPECT_EQ(layer.OccupiedCells(), 0);
  // Seen again, then not looked at: it fades below the threshold within a few decay times.
  layer.Integrate(SeeBox(10.0, true));
  layer.Integrate(SeeBox(10.4, true));
  layer.Integrate(SeeBox(10.8, true));
  ASSERT_GT(layer.OccupiedCells(), 0);
  ObstacleObservation nothing;  // no view: time passes
  nothing.stamp = 10.8 + 3.0 * parameters.decay_time;
  layer.Integrate(nothing);
  EXPECT_EQ(layer.OccupiedCells(), 0);
}

// The window rolls with the robot: every cell it keeps holds the same value at the same place in
// the map frame.
TEST(ObstacleLayer, RollsWithTheRobotKeepingCellsInPlace) {
  ObstacleLayerParameters parameters;
  parameters.decay_time = 1e6;  // no fading between the two looks
  ObstacleLayer layer(EmptyMap(), parameters);
  layer.Integrate(SeeBox(0.0, true));
  layer.Integrate(SeeBox(0.1, true));
  ASSERT_GT(layer.OccupiedCells(), 0);
  std::vector<std::pair<Eigen::Vector2d, double>> before;
  for (double x = 0.525; x < 3.0; x += 0.05) {
    for (double y = -0.475; y < 0.5; y += 0.05) before.push_back({{x, y}, layer.LogOdds({x, y})});
  }
  ObstacleObservation moved;
  moved.stamp = 0.2;
  ObstacleView view;
  view.sensor = {4.0, 1.0};  // beyond a quarter of the window: it recentres
  moved.views.push_back(view);
  layer.Integrate(moved);
  EXPECT_NEAR(layer.origin().x(), 4.0 - 6.0, 0.051);
  for (const auto& [point, value] : before) EXPECT_NEAR(layer.LogOdds(point), value, 1e-4) << point.transpose();
}

// Two pairs seeing the same cell in one frame count once.
TEST(ObstacleLayer, ACellSeenByTwoPairsInOneFrameCountsOnce) {
  ObstacleLayer layer(EmptyMap(), ObstacleLayerParameters{});
  ObstacleObservation both = SeeBox(0.0, true);
  both.views.push_back(both.views.front());
  layer.Integrate(both);
  EXPECT_EQ(layer.OccupiedCells(), 0) << "one frame, however many pairs, is one hit";
}

// Rendered: the front stereo pair sees a 0.4 x 0.4 x 0.3 m box 2.1 m ahead on the lawn (1.8 m from
// the cameras, where stereo's depth is good to ~5 cm and ground points behind the box's place
// still pass the point-uncertainty limit). Three
// frames mark it where it stands (and nothing else); with the box taken away, frames of the bare
// lawn clear it.
class RenderedObstacle : public ::testing::Test {
 protected:
  static std::string Garden(bool box) {
    const std::string objects =
        box ? "objects:\n  - {id: 1, class: obstacle, shape: box, size: [0.4, 0.4, 0.3], position: [2.3, 0.0]}\n"
            : "objects: []\n";
    return testing::WriteTempFile(box ? "box_ahead.yaml" : "no_box_ahead.yaml",
                                  "name: box_ahead\nseed: 3\nsize: [12, 12]\nground: grass\n" + objects);
  }
  // Integrates `frames` frames of the front pair from a robot standing at the origin facing +x.
  static void Observe(bool box, int frames, double* stamp, ObstacleLayer* layer) {
    sim::Simulator simulator(testing::TestConfig(Garden(box), box ? "box_ahead" : "no_box_ahead", true));
    const perception::RingStereo stereo(simulator.rig(), perception::StereoOptions{});
    const perception::StereoRectifier& front = stereo.rectifiers()[0];
    ASSERT_EQ(front.pair().left, 0);
    messages::RingRequest request;
    request.cameras = {std::min(front.pair().left, front.pair().right),
                       std::max(front.pair().left, front.pair().right)};
    for (int k = 0; k < frames; ++k) {
      const sim::RingCapture capture = simulator.CaptureRing(request, false);
      const auto result = stereo.ComputePair(capture.frame, 0);
      const auto points = perception::FindObstaclePoints(result.cloud, front.T_base_rectified_left().translation());
      ASSERT_TRUE(points.ground_fitted);
      ObstacleObservation o;
      o.stamp = *stamp;
      ObstacleView view;
      view.sensor = points.sensor.head<2>();  // base_link is the map frame here
      view.sensor_height = points.ground.Distance(points.sensor);
      for (const auto& p : points.obstacles) view.obstacles.push_back(p.head<2>());
      for (const auto& p : points.ground_points) view.ground.push_back(p.head<2>());
      o.views.push_back(view);
      layer->Integrate(o);
      *stamp += 0.4;
    }
  }
};

TEST_F(RenderedObstacle, BoxAheadIsMarkedWhereItStandsAndClearedWhenRemoved) {
  ObstacleLayer layer(EmptyMap(), ObstacleLayerParameters{});
  double stamp = 0.0;
  Observe(true, 3, &stamp, &layer);
  // The box covers x 2.1..2.5, y -0.2..0.2: its cells, and a margin of three standard deviations
  // of stereo depth at ~2 m (Z^2 / (f B) * 0.25 px = 7 cm; 3 sigma = 0.2 m).
  const int on_box = OccupiedIn(layer, {1.9, -0.4}, {2.7, 0.4});
  EXPECT_GE(OccupiedIn(layer, {2.1, -0.2}, {2.2, 0.2}), 6) << "the box's front face spans 8 cells";
  EXPECT_EQ(layer.OccupiedCells(), on_box) << "occupied cells away from the box";
  Observe(false, 8, &stamp, &layer);
  EXPECT_EQ(layer.OccupiedCells(), 0) << "the box is gone; its cells must be cleared";
}

}  // namespace
}  // namespace trimbot::stack
