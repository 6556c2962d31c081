// Rendered cameras against the calibration: targets land where the camera model predicts, depth
// is metric, a stereo pair's disparity is f*B/Z, and the same seed gives the same bytes.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>

#include "sim_test_support.h"
#include "trimbot/sim/camera_noise.h"

namespace trimbot::sim {
namespace {

using testing::SourcePath;
using testing::TestConfig;

std::string Targets() { return SourcePath("tests/data/camera_targets.yaml"); }

// Centroid (in pixels) of the pixels labelled with an object id; nullopt if too few.
std::optional<Eigen::Vector2d> Centroid(const cv::Mat& object_id, int id) {
  double sum_u = 0, sum_v = 0;
  int n = 0;
  for (int v = 0; v < object_id.rows; ++v) {
    for (int u = 0; u < object_id.cols; ++u) {
      if (object_id.at<uint16_t>(v, u) == id) {
        sum_u += u;
        sum_v += v;
        ++n;
      }
    }
  }
  if (n < 10) return std::nullopt;
  return Eigen::Vector2d(sum_u / n, sum_v / n);
}

Eigen::Vector3d TargetCentre(const garden::Garden& garden, int id) {
  for (const auto& object : garden.objects) {
    if (object.id == id) {
      return {object.position.x(), object.position.y(), object.base_height + object.size.z() / 2};
    }
  }
  throw std::runtime_error("no target " + std::to_string(id));
}

class RenderedTargets : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    simulator_ = new Simulator(TestConfig(Targets(), "targets", true));
    capture_ = new RingCapture(simulator_->CaptureRing(true));
  }
  static void TearDownTestSuite() {
    delete capture_;
    delete simulator_;
  }
  // Camera pose from ground truth of the base and the calibration (not from the renderer).
  static Eigen::Isometry3d T_map_camera(int index) {
    return simulator_->ground_truth().T_map_base * simulator_->rig().camera(index).T_base_camera;
  }
  static Simulator* simulator_;
  static RingCapture* capture_;
};
Simulator* RenderedTargets::simulator_ = nullptr;
RingCapture* RenderedTargets::capture_ = nullptr;

TEST_F(RenderedTargets, TargetsLandWhereTheCalibrationProjectsThem) {
  const auto& camera = simulator_->rig().camera(0).intrinsics;
  const cv::Mat& ids = capture_->truth.views[0].object_id;
  int checked = 0;
  double worst = 0.0;
  for (int id = 11; id <= 17; ++id) {
    const Eigen::Vector3d in_camera = T_map_camera(0).inverse() * TargetCentre(simulator_->garden(), id);
    const Eigen::Vector2d predicted = camera.Project(in_camera);
    const auto centroid = Centroid(ids, id);
    ASSERT_TRUE(centroid.has_value()) << "target " << id << " not visible";
    EXPECT_LT((*centroid - predicted).norm(), 1.0)
        << "target " << id << " at " << centroid->transpose() << ", predicted " << predicted.transpose();
    worst = std::max(worst, (*centroid - predicted).norm());
    ++checked;
  }
  EXPECT_EQ(checked, 7);
  std::printf("projection: worst target error %.3f px over %d targets\n", worst, checked);
  // Off-axis targets test the distortion: they are far from the principal point.
  const Eigen::Vector2d corner_target =
      camera.Project(T_map_camera(0).inverse() * TargetCentre(simulator_->garden(), 17));
  EXPECT_GT((corner_target - Eigen::Vector2d(camera.cx, camera.cy)).norm(), 250.0);
}

TEST_F(RenderedTargets, DepthOfTheWallIsThreeMetres) {
  const cv::Mat& depth = capture_->truth.views[0].depth;
  const cv::Mat& ids = capture_->truth.views[0].object_id;
  int n = 0;
  double worst = 0.0;
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      if (ids.at<uint16_t>(v, u) != 1) continue;
      // Skip the wall's silhouette, where nearest-neighbour resampling may pick a neighbour.
      bool interior = v > 0 && u > 0 && v + 1 < depth.rows && u + 1 < depth.cols;
      for (int dv = -1; interior && dv <= 1; ++dv) {
        for (int du = -1; interior && du <= 1; ++du) interior = ids.at<uint16_t>(v + dv, u + du) == 1;
      }
      if (!interior) continue;
      worst = std::max(worst, std::abs(depth.at<float>(v, u) - 3.0));
      ++n;
    }
  }
  EXPECT_GT(n, 50000);
  EXPECT_LT(worst, 0.01);
  std::printf("depth: worst error %.5f m over %d wall pixels at 3 m\n", worst, n);
}

TEST_F(RenderedTargets, StereoDisparityIsFocalTimesBaselineOverDepth) {
  const auto pair = simulator_->rig().StereoPairs()[0];
  const auto& left = simulator_->rig().camera(pair.left).intrinsics;
  const auto& right = simulator_->rig().camera(pair.right).intrinsics;
  double worst = 0.0;
  for (int id = 11; id <= 17; ++id) {
    const auto centroid_left = Centroid(capture_->truth.views[pair.left].object_id, id);
    const auto centroid_right = Centroid(capture_->truth.views[pair.right].object_id, id);
    ASSERT_TRUE(centroid_left && centroid_right) << "target " << id;
    // Undistort both centroids: the nominal pair is parallel, so disparity is along x only.
    const Eigen::Vector2d ray_left = left.Undistort(*centroid_left);
    const Eigen::Vector2d ray_right = right.Undistort(*centroid_right);
    const double disparity = left.fx * (ray_left.x() - ray_right.x());
    const double depth = (T_map_camera(pair.left).inverse() * TargetCentre(simulator_->garden(), id)).z();
    EXPECT_NEAR(disparity, left.fx * pair.baseline / depth, 0.25) << "target " << id << " at " << depth << " m";
    worst = std::max(worst, std::abs(disparity - left.fx * pair.baseline / depth));
    EXPECT_NEAR(ray_left.y(), ray_right.y(), 0.25 / left.fy) << "target " << id;  // same row after rectification
  }
  std::printf("stereo: worst disparity error %.3f px (f*B/Z from 16.2 px at 1 m to 5.8 px at 2.8 m)\n", worst);
}

TEST_F(RenderedTargets, LabelsNameTheObjectsAndTheGround) {
  const cv::Mat& classes = capture_->truth.views[0].object_class;
  std::map<int, int> count;
  for (int v = 0; v < classes.rows; ++v) {
    for (int u = 0; u < classes.cols; ++u) ++count[classes.at<uchar>(v, u)];
  }
  EXPECT_GT(count[static_cast<int>(garden::ObjectClass::kGround)], 10000);
  EXPECT_GT(count[static_cast<int>(garden::ObjectClass::kObstacle)], 50000);
  // No pixel carries an unknown class.
  for (const auto& [value, n] : count) EXPECT_LE(value, static_cast<int>(garden::ObjectClass::kRobot));
  // A rear camera sees sky: "nothing" there, and no depth exactly where nothing was hit.
  const cv::Mat& rear_classes = capture_->truth.views[5].object_class;
  const cv::Mat& rear_depth = capture_->truth.views[5].depth;
  const int sky = cv::countNonZero(rear_classes == 0);
  EXPECT_GT(sky, 50000);
  EXPECT_EQ(cv::countNonZero(rear_depth == 0.0f), sky);
}

// Same scenario and seed: the same bytes in images and IMU samples; another seed differs.
struct Recording {
  std::vector<std::vector<uint8_t>> images;
  std::vector<messages::ImuSample> imu;
  std::vector<messages::WheelTicks> ticks;
};

Recording Record(std::uint64_t seed, const std::string& name) {
  SimulatorConfig config = TestConfig(testing::TestLawn(), name, true);
  config.seed = seed;
  config.resolution_scale = 0.5;
  Simulator simulator(config);
  simulator.SetBaseCommand({0.25, 0.1});
  Recording recording;
  SensorOutputs outputs;
  GroundTruth truth_now;
  while (simulator.time() < 0.45) {  // two ring frames at 5 Hz
    outputs.Clear();
    simulator.Step(&outputs, &truth_now);
    recording.imu.insert(recording.imu.end(), outputs.imu.begin(), outputs.imu.end());
    recording.ticks.insert(recording.ticks.end(), outputs.wheel_ticks.begin(), outputs.wheel_ticks.end());
    if (outputs.ring) {
      for (const auto& image : outputs.ring->images) recording.images.push_back(image.data);
    }
  }
  return recording;
}

// What the stack asks for is what is rendered: only the named cameras, at the asked resolution
// (the same view as at another resolution), their ground truth in their own slots.
TEST(RingRequest, RendersOnlyTheNamedCamerasAtTheAskedResolution) {
  SimulatorConfig config = TestConfig(testing::TestLawn(), "ring_request", true);
  config.cameras_on_schedule = false;
  config.resolution_scale = 0.5;
  Simulator simulator(config);
  messages::RingRequest request;
  request.cameras = {1, 6};
  request.resolution_scale = 0.25;
  const RingCapture quarter = simulator.CaptureRing(request, true);
  ASSERT_EQ(quarter.frame.images.size(), 2u);
  EXPECT_EQ(quarter.frame.images[0].camera_index, 1);
  EXPECT_EQ(quarter.frame.images[1].camera_index, 6);
  EXPECT_EQ(quarter.frame.images[1].width, 188);
  EXPECT_EQ(quarter.frame.images[1].height, 120);
  ASSERT_EQ(quarter.truth.views.size(), static_cast<std::size_t>(simulator.rig().size()));
  EXPECT_TRUE(quarter.truth.views[0].depth.empty());
  EXPECT_EQ(quarter.truth.views[6].depth.rows, 120);
  EXPECT_EQ(quarter.truth.T_map_camera.size(), static_cast<std::size_t>(simulator.rig().size()));

  // The whole ring at the configured (half) resolution, shrunk to a quarter: the same picture.
  const RingCapture half = simulator.CaptureRing(false);
  ASSERT_EQ(half.frame.images.size(), static_cast<std::size_t>(simulator.rig().size()));
  const auto& big = half.frame.images[6];
  const auto& small = quarter.frame.images[1];
  cv::Mat shrunk;
  cv::resize(cv::Mat(big.height, big.width, CV_8UC3, const_cast<uint8_t*>(big.data.data())), shrunk,
             cv::Size(small.width, small.height), 0, 0, cv::INTER_AREA);
  cv::Mat difference;
  cv::absdiff(shrunk, cv::Mat(small.height, small.width, CV_8UC3, const_cast<uint8_t*>(small.data.data())), difference);
  EXPECT_LT(cv::mean(difference)[0], 12.0) << "grey levels: the quarter-size view is the half-size view, smaller";

  EXPECT_TRUE(messages::Merge({{0, 2}, 0.5}, {}).cameras == std::vector<int>({0, 2}));
  const messages::RingRequest both = messages::Merge({{0, 2, 4}, 0.5}, {{1, 2}, 1.0});
  EXPECT_EQ(both.cameras, std::vector<int>({0, 1, 2, 4}));
  EXPECT_EQ(both.resolution_scale, 1.0);
}

// Read noise from the bank: zero mean, the asked sigma, the same image seed the same noise, another
// seed other noise; the signal scaled by the exposure; saturates instead of wrapping, and clips the
// noise of a pixel the exposure saturated.
TEST(ReadNoise, HasTheAskedSigmaAndIsReproducible) {
  const ReadNoise noise(5);
  cv::Mat a(240, 376, CV_8UC3, cv::Scalar(64, 64, 64));
  cv::Mat b = a.clone(), c = a.clone();
  noise.ReadOut(a, 2.0, 2.0, 11);
  noise.ReadOut(b, 2.0, 2.0, 11);
  noise.ReadOut(c, 2.0, 2.0, 12);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1), 0.0);
  cv::Scalar mean, sigma;
  cv::meanStdDev(a.reshape(1), mean, sigma);
  EXPECT_NEAR(mean[0], 128.0, 0.05);
  EXPECT_NEAR(sigma[0], 2.0, 0.1);  // rounding to grey levels adds 1/12 to the variance
  cv::Mat white(10, 10, CV_8UC3, cv::Scalar(255, 255, 255));
  noise.ReadOut(white, 1.0, 50.0, 3);
  double lowest = 0.0;
  cv::minMaxLoc(white.reshape(1), &lowest);
  EXPECT_LT(lowest, 255.0);
  EXPECT_GT(cv::mean(white)[0], 200.0) << "saturated at 255, not wrapped to dark";
  cv::Mat overexposed(10, 10, CV_8UC3, cv::Scalar(200, 200, 200));
  noise.ReadOut(overexposed, 2.0, 2.0, 4);
  cv::minMaxLoc(overexposed.reshape(1), &lowest);
  EXPECT_EQ(lowest, 255.0) << "400 grey levels of signal stay clipped at 255 with noise of 2";
}

// Each camera draws only the geoms in its view volume or casting a shadow into it: the same
// pixels and labels as drawing the whole garden, with a low sun (long shadows from behind), from
// two headings (so that objects straddle image edges in some of the ten cameras).
TEST(FrustumCulling, DrawsTheSameImagesWithFewerGeoms) {
  for (const double yaw : {0.0, 0.45}) {
    RingCapture captures[2];
    SimulatorTimings timings[2];
    for (const bool culling : {false, true}) {
      SimulatorConfig config = TestConfig(testing::TestLawn(), culling ? "culling_on" : "culling_off", true);
      config.conditions.time_of_day = 18.5;
      config.resolution_scale = 0.5;
      config.start.yaw = yaw;
      config.frustum_culling = culling;
      Simulator simulator(config);
      captures[culling] = simulator.CaptureRing(true);
      timings[culling] = simulator.timings();
    }
    EXPECT_EQ(timings[0].geoms_culled, 0);
    EXPECT_GT(timings[1].geoms_culled, timings[1].geoms_drawn / 4) << "most cameras see part of the garden";
    EXPECT_EQ(timings[1].geoms_drawn + timings[1].geoms_culled, timings[0].geoms_drawn);
    ASSERT_EQ(captures[0].frame.images.size(), captures[1].frame.images.size());
    for (std::size_t i = 0; i < captures[0].frame.images.size(); ++i) {
      EXPECT_TRUE(captures[0].frame.images[i].data == captures[1].frame.images[i].data)
          << "camera " << i << " yaw " << yaw;
      const RenderedView& off = captures[0].truth.views[i];
      const RenderedView& on = captures[1].truth.views[i];
      EXPECT_EQ(cv::norm(off.object_id, on.object_id, cv::NORM_INF), 0.0) << "camera " << i << " yaw " << yaw;
      EXPECT_EQ(cv::norm(off.depth, on.depth, cv::NORM_INF), 0.0) << "camera " << i << " yaw " << yaw;
    }
  }
}

// Nothing stands in the sun: the sun's shadows must change nothing on the ground (a gravel path
// on the lawn), at noon and with a low evening sun. Before the ground's slabs reached deep
// enough, the ground shadowed itself in stripes ("acne") where the shadow map's texels spanned
// more depth than the slab.
TEST(GroundShadows, GroundWithNothingOnItDoesNotShadowItself) {
  const std::string garden =
      testing::WriteTempFile("bare_path.yaml",
                             "name: bare_path\nseed: 4\nsize: [24, 24]\nground: grass\n"
                             "paths:\n  - {surface: gravel, centre: [6.0, 0.0], size: [10.0, 1.2]}\nobjects: []\n");
  for (const double hour : {12.0, 18.0}) {
    cv::Mat images[2];
    for (const bool shadows : {false, true}) {
      SimulatorConfig config = TestConfig(garden, shadows ? "bare_path_shadows" : "bare_path_flat", true);
      config.conditions.time_of_day = hour;
      config.conditions.shadows = shadows;
      Simulator simulator(config);
      messages::RingRequest front;
      front.cameras = {0};
      const RingCapture capture = simulator.CaptureRing(front, false);
      const auto& image = capture.frame.images[0];
      images[shadows] = cv::Mat(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.data.data())).clone();
    }
    // Rows above the bottom quarter: the robot's own shadow lies close in front of it.
    const cv::Rect far(0, 0, images[0].cols, images[0].rows * 3 / 4);
    cv::Mat difference;
    cv::absdiff(images[0](far), images[1](far), difference);
    cv::Mat grey;
    cv::cvtColor(difference, grey, cv::COLOR_RGB2GRAY);
    const double stripes = cv::countNonZero(grey > 12) / static_cast<double>(grey.total());
    EXPECT_LT(stripes, 0.002) << "at " << hour << " h, pixels darkened by the ground's own shadow";
  }
}

TEST(Determinism, SameSeedSameBytes) {
  const Recording a = Record(42, "determinism_a");
  const Recording b = Record(42, "determinism_b");
  const Recording c = Record(43, "determinism_c");
  ASSERT_EQ(a.images.size(), 20u);
  ASSERT_EQ(a.images.size(), b.images.size());
  for (size_t i = 0; i < a.images.size(); ++i) EXPECT_TRUE(a.images[i] == b.images[i]) << "image " << i;
  ASSERT_EQ(a.imu.size(), b.imu.size());
  ASSERT_GT(a.imu.size(), 80u);
  for (size_t i = 0; i < a.imu.size(); ++i) {
    EXPECT_EQ(std::memcmp(&a.imu[i], &b.imu[i], sizeof(messages::ImuSample)), 0) << "IMU sample " << i;
  }
  for (size_t i = 0; i < a.ticks.size(); ++i) EXPECT_EQ(a.ticks[i].left, b.ticks[i].left);
  // Another seed: different image noise and IMU noise.
  EXPECT_FALSE(a.images[0] == c.images[0]);
  EXPECT_NE(a.imu[0].angular_velocity.x(), c.imu[0].angular_velocity.x());
}

}  // namespace
}  // namespace trimbot::sim
