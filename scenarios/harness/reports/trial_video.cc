#include "reports/trial_video.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "reports/drawing.h"
#include "reports/output_files.h"
#include "trimbot/common/input_error.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {
namespace {

constexpr int kSideWidth = 376;  // the ring's cam0 at half size (752 x 480)

// BGR colours (the video writer's order).
const cv::Scalar kTruthBgr(40, 40, 40);
const cv::Scalar kEstimateBgr(200, 110, 30);
const cv::Scalar kRobotBgr(30, 30, 220);

}  // namespace

TrialVideo::TrialVideo(std::string path, sim::Simulator& simulator, const garden::OccupancyMap& map,
                       TrialVideoOptions options)
    : path_(std::move(path)), simulator_(simulator), map_(map), options_(options) {
  const int width = options_.height * 4 / 3 + kSideWidth;
  // H.264 ("avc1"): what browsers play inside report.html.
  writer_.open(Partial(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('a', 'v', 'c', '1'), options_.rate,
               cv::Size(width, options_.height));
  if (!writer_.isOpened()) throw InputError(path_, "the video writer (OpenCV, FFmpeg, H.264) cannot write it");
}

// FFmpeg picks the container by the extension: trial.partial.mp4 while it is written.
std::string TrialVideo::Partial() const {
  return std::filesystem::path(path_).replace_extension(".partial.mp4").string();
}

void TrialVideo::Observe(const StepView& step) {
  const Eigen::Vector3d position = step.truth.T_map_base.translation();
  if (truth_path_.empty() || (cv::Point2d(position.x(), position.y()) - truth_path_.back())
                                     .dot(cv::Point2d(position.x(), position.y()) - truth_path_.back()) > 1e-4) {
    truth_path_.emplace_back(position.x(), position.y());
  }
  if (step.telemetry != nullptr) {
    const Pose2& estimate = step.telemetry->estimate.pose;
    if (estimate_path_.empty() ||
        std::hypot(estimate.x - estimate_path_.back().x, estimate.y - estimate_path_.back().y) > 0.01)
      estimate_path_.emplace_back(estimate.x, estimate.y);
  }
  if (step.sensors.ring) {
    for (const auto& image : step.sensors.ring->images) {
      if (image.camera_index != 0 || image.encoding != "rgb8") continue;
      cv::cvtColor(ImageView(image), last_camera_, cv::COLOR_RGB2BGR);
    }
  }
  if (step.time + 1e-9 < next_frame_) return;
  next_frame_ = NextSampleTime(step.time, options_.rate);

  const int height = options_.height, external_width = height * 4 / 3;
  cv::Mat frame(height, external_width + kSideWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  // The external camera: behind the robot, looking along its heading.
  const Eigen::Matrix3d R = step.truth.T_map_base.rotation();
  const double yaw_deg = std::atan2(R(1, 0), R(0, 0)) * 180.0 / M_PI;
  cv::Mat external = simulator_.RenderExternalView(position + Eigen::Vector3d(0.0, 0.0, 0.4), options_.follow_distance,
                                                   yaw_deg, options_.follow_elevation, external_width, height);
  cv::cvtColor(external, external, cv::COLOR_RGB2BGR);
  if (external.size() != cv::Size(external_width, height)) cv::resize(external, external, {external_width, height});
  external.copyTo(frame(cv::Rect(0, 0, external_width, height)));
  // The ring's cam0 as the stack last got it (nothing until the stack asks for a frame).
  const int camera_height = kSideWidth * 480 / 752;
  if (!last_camera_.empty()) {
    cv::Mat small;
    cv::resize(last_camera_, small, cv::Size(kSideWidth, camera_height), 0, 0, cv::INTER_AREA);
    small.copyTo(frame(cv::Rect(external_width, 0, kSideWidth, camera_height)));
  }
  PutText(frame, "cam0", {external_width + 6, 18}, 0.5, kWhite, 1);
  const cv::Rect top(external_width, camera_height, kSideWidth, height - camera_height);
  TopView(step).copyTo(frame(top));
  char stamp[64];
  std::snprintf(stamp, sizeof stamp, "t = %.1f s", step.time);
  PutText(frame, stamp, {10, 26}, 0.7, kWhite, 2);
  writer_.write(frame);
  ++frames_;
}

// The robot's map around the robot (4 m across), the true path dark, the EKF's blue, the robot red.
cv::Mat TrialVideo::TopView(const StepView& step) const {
  const int height = options_.height - kSideWidth * 480 / 752;
  cv::Mat view(height, kSideWidth, CV_8UC3, cv::Scalar(245, 245, 245));
  const Eigen::Vector3d centre = step.truth.T_map_base.translation();
  const double metres_per_px = 4.0 / kSideWidth;
  const auto pixel = [&](const cv::Point2d& p) {
    return cv::Point2d(kSideWidth / 2.0 + (p.x - centre.x()) / metres_per_px,
                       height / 2.0 - (p.y - centre.y()) / metres_per_px);
  };
  if (!map_.occupied.empty()) {
    // The map's cells under the view's pixels in one resampling: pixel (col, row) is the map point
    // centre + metres_per_px (col - w/2, -(row - h/2)), whose cell OccupancyMap::Cell gives
    // (nearest neighbour rounds where Cell floors: the half cell taken off).
    const double scale = metres_per_px / map_.resolution;
    const cv::Matx23d view_to_cell(
        scale, 0.0, (centre.x() - map_.origin.x()) / map_.resolution - kSideWidth / 2.0 * scale - 0.5,  //
        0.0, scale, map_.occupied.rows - 0.5 - (centre.y() - map_.origin.y()) / map_.resolution - height / 2.0 * scale);
    cv::Mat occupied;
    cv::warpAffine(map_.occupied, occupied, view_to_cell, view.size(), cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                   cv::BORDER_CONSTANT, 0);
    view.setTo(cv::Scalar(120, 120, 120), occupied > 0);
  }
  const auto polyline = [&](const std::vector<cv::Point2d>& path, const cv::Scalar& colour, int thickness) {
    for (std::size_t i = 1; i < path.size(); ++i)
      cv::line(view, FixedPoint(pixel(path[i - 1])), FixedPoint(pixel(path[i])), colour, thickness, cv::LINE_AA,
               kSubpixelBits);
  };
  polyline(truth_path_, kTruthBgr, 2);
  polyline(estimate_path_, kEstimateBgr, 1);
  const Eigen::Matrix3d R = step.truth.T_map_base.rotation();
  const cv::Point2d robot = pixel({centre.x(), centre.y()});
  const cv::Point2d nose = pixel({centre.x() + 0.35 * R(0, 0), centre.y() + 0.35 * R(1, 0)});
  cv::circle(view, FixedPoint(robot), 8 << kSubpixelBits, kRobotBgr, 2, cv::LINE_AA, kSubpixelBits);
  cv::line(view, FixedPoint(robot), FixedPoint(nose), kRobotBgr, 2, cv::LINE_AA, kSubpixelBits);
  PutText(view, "top view: truth (dark), EKF (blue)", {6, 16}, 0.42, kInk, 1);
  return view;
}

void TrialVideo::Close() {
  writer_.release();
  std::filesystem::rename(Partial(), path_);
}

}  // namespace trimbot::scenarios
