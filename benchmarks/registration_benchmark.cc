// Registration time per pair: DUGMA and the baselines through the same API (Open3D's ICP,
// point-to-plane ICP and generalized ICP), on the same synthetic garden clouds of 1k-64k points (20 deg, 0.5 m from the
// identity guess), with the errors as counters; and DUGMA on the Kinect pairs of the DUGMA data set when it is there
// (TRIMBOT_DUGMA_DATA, default ../shared/data/dugma_kinect beside the source tree).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>

#include "evaluation/pose_errors.h"
#include "evaluation/registration_pair_file.h"
#include "synthetic_clouds.h"
#include "trimbot/perception/registration.h"

namespace {

using namespace trimbot::perception;
using trimbot::scenarios::RotationErrorDegrees;
using trimbot::scenarios::TranslationError;

struct Pair {
  PointCloud x, y;
  Eigen::Isometry3d truth;
};

const Pair& SyntheticPair(int points) {
  static std::map<int, Pair> cache;
  auto it = cache.find(points);
  if (it == cache.end()) {
    Pair pair;
    pair.x = GardenScene(points, 11, false);
    pair.truth = Transform(20.0, 5.0, {0.4, -0.3, 0.1});
    pair.y = ObservedFrom(GardenScene(2 * points, 11, false), pair.truth, 12);  // as many points as x
    it = cache.emplace(points, std::move(pair)).first;
  }
  return it->second;
}

void Report(benchmark::State& state, const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  state.counters["rot_err_deg"] = RotationErrorDegrees(estimate, truth);
  state.counters["trans_err_m"] = TranslationError(estimate, truth);
}

void BM_Register(benchmark::State& state, RegistrationMethod method) {
  const Pair& pair = SyntheticPair(static_cast<int>(state.range(0)));
  RegistrationOptions options;
  options.method = method;
  RegistrationResult result;
  for (auto _ : state) {
    result = Register(pair.x, pair.y, Eigen::Isometry3d::Identity(), options);
    benchmark::DoNotOptimize(result);
  }
  Report(state, result.transform, pair.truth);
  state.counters["iterations"] = result.iterations;
}
BENCHMARK_CAPTURE(BM_Register, dugma, RegistrationMethod::kDugma)
    ->Arg(1000)
    ->Arg(4000)
    ->Arg(16000)
    ->Arg(64000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Register, icp, RegistrationMethod::kIcpPointToPoint)
    ->Arg(1000)
    ->Arg(4000)
    ->Arg(16000)
    ->Arg(64000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Register, icp_plane, RegistrationMethod::kIcpPointToPlane)
    ->Arg(1000)
    ->Arg(4000)
    ->Arg(16000)
    ->Arg(64000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Register, generalized_icp, RegistrationMethod::kGeneralizedIcp)
    ->Arg(1000)
    ->Arg(4000)
    ->Arg(16000)
    ->Arg(64000)
    ->Unit(benchmark::kMillisecond);

// The Kinect pairs, one benchmark per pair, registered from the identity as in the data set.
void RegisterKinectPairs() {
  const char* env = std::getenv("TRIMBOT_DUGMA_DATA");
  const std::filesystem::path folder =
      env ? env : std::filesystem::path(TRIMBOT_SOURCE_DIR) / "../shared/data/dugma_kinect";
  if (!std::filesystem::is_directory(folder)) return;
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  for (const auto& file : files) {
    auto pair = std::make_shared<trimbot::scenarios::RegistrationPair>(trimbot::scenarios::LoadRegistrationPair(file));
    benchmark::RegisterBenchmark(("BM_DugmaKinect/" + pair->name).c_str(), [pair](benchmark::State& state) {
      RegistrationOptions options;
      options.relative_covariances = true;
      options.max_variance = 1e5;
      RegistrationResult result;
      for (auto _ : state) {
        result = Register(pair->x, pair->y, Eigen::Isometry3d::Identity(), options);
        benchmark::DoNotOptimize(result);
      }
      Report(state, result.transform, pair->truth);
    })->Unit(benchmark::kMillisecond);
  }
}

}  // namespace

int main(int argc, char** argv) {
  RegisterKinectPairs();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
