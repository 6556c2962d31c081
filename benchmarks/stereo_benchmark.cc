// Stereo cost at the ring's full resolution (752x480): rectification + SGM for one pair with the
// robot's 32 disparities and the dense option, the cloud with covariances, and the whole ring.
// The images are rendered once (test_lawn, facing the bushes) outside the timed loops; OpenCV
// keeps its default threading (the thread count is in the context), so times are wall-clock.
#include <benchmark/benchmark.h>

#include <opencv2/core/utility.hpp>

#include <filesystem>
#include <string>

#include "trimbot/perception/stereo.h"
#include "trimbot/sim/simulator.h"

namespace {

using namespace trimbot;

std::string SourcePath(const std::string& relative) { return std::string(TRIMBOT_SOURCE_DIR) + "/" + relative; }

struct Scene {
  robot::CameraRig rig;
  messages::RingFrame frame;
};

const Scene& RenderedScene() {
  static const Scene scene = [] {
    sim::SimulatorConfig config;
    config.robot = trimbot::robot::RobotFiles::InFolder(SourcePath("robot"));
    config.garden = garden::Garden::Load(SourcePath("garden_scenes/gardens/test_lawn.yaml"));
    config.world_dir = (std::filesystem::temp_directory_path() / "trimbot_stereo_benchmark_world").string();
    config.seed = 1;
    config.render_cameras = true;
    sim::Simulator simulator(config);
    return Scene{simulator.rig(), simulator.CaptureRing(false).frame};
  }();
  return scene;
}

perception::StereoOptions Options(bool dense) {
  perception::StereoOptions options;
  options.dense = dense;
  return options;
}

// Argument: OpenCV threads (0: OpenCV's default, one per core).
void RectifyAndMatchPair(benchmark::State& state, bool dense) {
  const Scene& scene = RenderedScene();
  const int default_threads = cv::getNumThreads();
  if (state.range(0) > 0) cv::setNumThreads(static_cast<int>(state.range(0)));
  state.counters["opencv_threads"] = cv::getNumThreads();
  const perception::RingStereo stereo(scene.rig, Options(dense));
  const perception::StereoRectifier& rectifier = stereo.rectifiers()[0];
  const cv::Mat left = perception::ImageToMat(scene.frame.images[0]);
  const cv::Mat right = perception::ImageToMat(scene.frame.images[1]);
  for (auto _ : state) {
    const auto rectified = rectifier.Rectify(left, right);
    benchmark::DoNotOptimize(stereo.matcher().Compute(rectified.left, rectified.right).data);
  }
  state.counters["disparities"] = Options(dense).EffectiveDisparities();
  cv::setNumThreads(default_threads);
}

void BM_RectifyAndSgm32(benchmark::State& state) { RectifyAndMatchPair(state, false); }
void BM_RectifyAndSgmDense(benchmark::State& state) { RectifyAndMatchPair(state, true); }

void BM_Rectify(benchmark::State& state) {
  const Scene& scene = RenderedScene();
  const perception::StereoRectifier rectifier(scene.rig, scene.rig.StereoPairs()[0]);
  const cv::Mat left = perception::ImageToMat(scene.frame.images[0]);
  const cv::Mat right = perception::ImageToMat(scene.frame.images[1]);
  for (auto _ : state) benchmark::DoNotOptimize(rectifier.Rectify(left, right).left.data);
}

void BM_DisparityToCloud(benchmark::State& state) {
  const Scene& scene = RenderedScene();
  const perception::RingStereo stereo(scene.rig);
  const cv::Mat disparity = stereo.ComputePair(scene.frame, 0).disparity;
  std::size_t points = 0;
  for (auto _ : state) {
    const perception::PointCloud cloud = perception::DisparityToCloud(disparity, stereo.rectifiers()[0]);
    points = cloud.size();
    benchmark::DoNotOptimize(cloud.points.data());
  }
  state.counters["points"] = static_cast<double>(points);
}

// Arguments: dense (0/1), pixel stride of the cloud.
void BM_RingCloud(benchmark::State& state) {
  const Scene& scene = RenderedScene();
  perception::StereoOptions options = Options(state.range(0) != 0);
  options.stride = static_cast<int>(state.range(1));
  const perception::RingStereo stereo(scene.rig, options);
  std::size_t points = 0;
  for (auto _ : state) {
    const perception::PointCloud cloud = stereo.RingCloud(scene.frame);
    points = cloud.size();
    benchmark::DoNotOptimize(cloud.points.data());
  }
  state.counters["points"] = static_cast<double>(points);
  state.counters["pairs"] = static_cast<double>(stereo.rectifiers().size());
}

// As a robot's loop would run it: one cloud whose memory is reused frame after frame.
void BM_RingCloudReused(benchmark::State& state) {
  const Scene& scene = RenderedScene();
  const perception::RingStereo stereo(scene.rig);
  perception::PointCloud cloud;
  for (auto _ : state) {
    stereo.RingCloud(scene.frame, &cloud);
    benchmark::DoNotOptimize(cloud.points.data());
  }
  state.counters["points"] = static_cast<double>(cloud.size());
}

BENCHMARK(BM_Rectify)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RectifyAndSgm32)->ArgName("threads")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RectifyAndSgmDense)->ArgName("threads")->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DisparityToCloud)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RingCloud)
    ->ArgNames({"dense", "stride"})
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_RingCloudReused)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::AddCustomContext("opencv_threads", std::to_string(cv::getNumThreads()));
  benchmark::AddCustomContext("image_size", "752x480");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
