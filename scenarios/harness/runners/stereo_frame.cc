#include "runners/stereo_frame.h"

#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "evaluation/stereo_evaluation.h"
#include "loop/setting.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/perception/stereo.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {
namespace {

// Disparity in a colour map from 0 to the matcher's largest disparity (the same scale for
// estimate and ground truth, so they compare by eye); black where there is none.
cv::Mat ColouriseDisparity(const cv::Mat& disparity, int disparities) {
  cv::Mat scaled(disparity.size(), CV_8U, cv::Scalar(0));
  cv::Mat valid(disparity.size(), CV_8U, cv::Scalar(0));
  for (int v = 0; v < disparity.rows; ++v) {
    for (int u = 0; u < disparity.cols; ++u) {
      const float d = disparity.at<float>(v, u);
      if (std::isnan(d)) continue;
      scaled.at<uchar>(v, u) = cv::saturate_cast<uchar>(255.0 * d / (disparities - 1));
      valid.at<uchar>(v, u) = 255;
    }
  }
  cv::Mat colour;
  cv::applyColorMap(scaled, colour, cv::COLORMAP_TURBO);
  cv::Mat out(disparity.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  colour.copyTo(out, valid);
  return out;
}

const messages::Image& ImageOf(const messages::RingFrame& frame, int camera_index) {
  for (const auto& image : frame.images) {
    if (image.camera_index == camera_index) return image;
  }
  throw std::runtime_error("the ring frame has no image from cam" + std::to_string(camera_index));
}

void WriteImage(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error("cannot write " + path);
}

// ASCII PLY: position and the diagonal of the covariance, both in base_link.
void WriteCloudPly(const std::string& path, const perception::PointCloud& cloud) {
  std::ostringstream ply;
  ply << "ply\nformat ascii 1.0\ncomment stereo ring cloud in base_link (m, m^2)\nelement vertex " << cloud.size()
      << "\nproperty float x\nproperty float y\nproperty float z\n"
         "property float var_x\nproperty float var_y\nproperty float var_z\nend_header\n";
  char line[160];
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.points[i];
    const Eigen::Matrix3d& c = cloud.covariances[i];
    std::snprintf(line, sizeof line, "%.4f %.4f %.4f %.4g %.4g %.4g\n", p.x(), p.y(), p.z(), c(0, 0), c(1, 1), c(2, 2));
    ply << line;
  }
  WriteFileAtomically(path, ply.str());
}

}  // namespace

int RunStereoFrame(const StereoFrameOptions& options, const ProjectPaths& paths) {
  namespace fs = std::filesystem;
  Setting setting;
  setting.garden = options.garden;
  setting.seed = options.seed;
  setting.start = {options.x, options.y, options.yaw_degrees * M_PI / 180.0};
  sim::SimulatorConfig config =
      MakeSimulatorConfig(paths, setting, LoadGarden(setting, paths), options.output + "/world");
  fs::create_directories(options.output);
  sim::Simulator simulator(config);
  const sim::RingCapture capture = simulator.CaptureRing(true);

  perception::StereoOptions stereo_options;
  stereo_options.dense = options.dense;
  stereo_options.stride = options.stride;
  // The robot's calibration: the simulator renders the cameras from the same file.
  const perception::RingStereo stereo(simulator.rig(), stereo_options);
  const int disparities = stereo_options.EffectiveDisparities();
  const perception::StereoRectifier& first = stereo.rectifiers().front();
  std::printf(
      "stereo: %s at (%.2f, %.2f) yaw %.1f deg, %d disparities (%s), OpenCV threads %d\n"
      "rectified: f %.1f px, baseline %.4f m (f B %.2f px m), horizontal field of view %.1f deg\n",
      options.garden.c_str(), options.x, options.y, options.yaw_degrees, disparities,
      options.dense ? "8-path SGM" : "3-way SGM", cv::getNumThreads(), first.focal_length(), first.baseline(),
      first.focal_length() * first.baseline(),
      2.0 * std::atan(0.5 * first.image_size().width / first.focal_length()) * 180.0 / M_PI);
  // spur %: estimates where the renderer saw nothing (sky), i.e. phantom points.
  std::printf("%-5s %-10s %9s %8s %8s %8s %8s %8s %9s\n", "pair", "cameras", "time ms", "MAE px", "bad-1 %", "bad-2 %",
              "compl %", "spur %", "points");
  stereo.ComputePair(capture.frame, 0);  // warm-up (OpenCV's threads, SGM buffers): not timed
  perception::PointCloud ring;
  double total_ms = 0.0;
  for (std::size_t k = 0; k < stereo.rectifiers().size(); ++k) {
    const perception::StereoRectifier& rectifier = stereo.rectifiers()[k];
    const auto start = std::chrono::steady_clock::now();
    const auto result = stereo.ComputePair(capture.frame, static_cast<int>(k));
    const double ms = 1000.0 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    total_ms += ms;
    const cv::Mat& left_depth = capture.truth.views[static_cast<std::size_t>(rectifier.pair().left)].depth;
    const cv::Mat truth = GroundTruthDisparity(rectifier, left_depth);
    const StereoErrors errors = EvaluateDisparity(result.disparity, truth, disparities);
    const std::string cameras =
        "cam" + std::to_string(rectifier.pair().left) + "/cam" + std::to_string(rectifier.pair().right);
    std::printf("%-5zu %-10s %9.1f %8.3f %8.2f %8.2f %8.1f %8.2f %9zu\n", k, cameras.c_str(), ms, errors.mean_abs_error,
                errors.bad1_percent, errors.bad2_percent, errors.completeness_percent, errors.spurious_percent,
                result.cloud.size());
    const std::string prefix = options.output + "/pair" + std::to_string(k);
    WriteImage(prefix + "_disparity.png", ColouriseDisparity(result.disparity, disparities));
    const cv::Mat left_image = perception::ImageToMat(ImageOf(capture.frame, rectifier.pair().left));
    WriteImage(prefix + "_left_rectified.png", rectifier.Rectify(left_image, left_image).left);
    WriteImage(prefix + "_gt_disparity.png", ColouriseDisparity(truth, disparities));
    ring.points.insert(ring.points.end(), result.cloud.points.begin(), result.cloud.points.end());
    ring.covariances.insert(ring.covariances.end(), result.cloud.covariances.begin(), result.cloud.covariances.end());
  }
  std::printf("ring: %.1f ms for %zu pairs, %zu points\n", total_ms, stereo.rectifiers().size(), ring.size());
  WriteCloudPly(options.output + "/ring_cloud.ply", ring);
  std::printf("wrote %s/pair{0..%zu}_{disparity,gt_disparity,left_rectified}.png and ring_cloud.ply (stride %d)\n",
              options.output.c_str(), stereo.rectifiers().size() - 1, options.stride);
  return 0;
}

}  // namespace trimbot::scenarios
