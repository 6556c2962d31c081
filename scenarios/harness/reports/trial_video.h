#pragma once
// trials/NNN/trial.mp4 (`trimbot run --video`): what happened in a trial, to watch. Each frame,
// side by side: an external camera following the robot from behind, the ring's cam0 as the stack
// last received it, and a top view of the robot's map with the true path, the EKF's estimate and
// the robot; simulated time in the corner. H.264 through OpenCV's video writer (Debian's FFmpeg
// backend), so browsers play it in report.html. Written to trial.partial.mp4, renamed at Close().
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "loop/closed_loop.h"
#include "trimbot/garden/garden_tools.h"

namespace trimbot::scenarios {

struct TrialVideoOptions {
  double rate = 5.0;              // frames per simulated second (the ring's rate)
  int height = 480;               // px of the external view; the other panels beside it
  double follow_distance = 3.0;   // m from the robot to the external camera
  double follow_elevation = -25;  // deg (looking down)
};

class TrialVideo : public Observer {
 public:
  // `simulator` renders the external view; `map` is the robot's prior map (top view). Throws
  // InputError naming the file when the writer cannot open it.
  TrialVideo(std::string path, sim::Simulator& simulator, const garden::OccupancyMap& map,
             TrialVideoOptions options = {});
  void Observe(const StepView& step) override;
  void Close();

  long frames() const { return frames_; }

 private:
  cv::Mat TopView(const StepView& step) const;
  std::string Partial() const;

  std::string path_;
  sim::Simulator& simulator_;
  garden::OccupancyMap map_;
  TrialVideoOptions options_;
  cv::VideoWriter writer_;
  cv::Mat last_camera_;  // BGR
  std::vector<cv::Point2d> truth_path_, estimate_path_;
  double next_frame_ = 0.0;
  long frames_ = 0;
};

}  // namespace trimbot::scenarios
