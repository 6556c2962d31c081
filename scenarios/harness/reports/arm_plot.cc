#include "reports/arm_plot.h"

#include <algorithm>
#include <limits>

#include "reports/drawing.h"
#include "reports/output_files.h"

namespace trimbot::scenarios {
namespace {

const cv::Scalar kReachedColour(60, 150, 60), kFailedColour(200, 40, 40), kClearance(40, 110, 200),
    kTracking(220, 120, 40);

}  // namespace

void WriteArmReachPlot(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials) {
  std::vector<cv::Point2d> top_reached, top_failed, side_reached, side_failed, position_mm, clearance_cm, tracking_mrad;
  double n = 0.0;
  for (const TrialResult& trial : trials) {
    for (const ArmGoalOutcome& goal : trial.arm_goals) {
      (goal.reached ? top_reached : top_failed).emplace_back(goal.x, goal.y);
      (goal.reached ? side_reached : side_failed).emplace_back(goal.x, goal.z);
      if (goal.stack_reached) position_mm.emplace_back(n, 1000.0 * goal.position_error_m);
      if (goal.min_clearance_m >= 0.0) clearance_cm.emplace_back(n, 100.0 * goal.min_clearance_m);
      tracking_mrad.emplace_back(n, 1000.0 * goal.tracking_error_max_rad);
      n += 1.0;
    }
  }
  if (n == 0.0) return;
  cv::Mat image(760, 1200, CV_8UC3, kWhite);
  PutText(image, title, {16, 30}, 0.6, kInk, 2);
  Legend(image, 58,
         {{"reached", kReachedColour},
          {"not reached", kFailedColour},
          {"min clearance (cm)", kClearance},
          {"tracking error (mrad)", kTracking}});
  // Poses in base_link: x forward, y left (from above) and z up (from the side).
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto* points : {&top_reached, &top_failed}) Extent(*points, &x0, &x1, &y0, &y1);
  Panel top(image, {80, 100, 480, 280}, x0 - 0.05, x1 + 0.05, y0, y1,
            "cutter goals from above: y (m) over x (m), base_link");
  top.Dots(top_reached, kReachedColour, 4);
  top.Dots(top_failed, kFailedColour, 4);
  y0 = std::numeric_limits<double>::infinity(), y1 = -y0;
  for (const auto* points : {&side_reached, &side_failed}) Extent(*points, &x0, &x1, &y0, &y1);
  Panel side(image, {660, 100, 480, 280}, x0 - 0.05, x1 + 0.05, y0, y1, "cutter goals from the side: z (m) over x (m)");
  side.Dots(side_reached, kReachedColour, 4);
  side.Dots(side_failed, kFailedColour, 4);
  // Per goal, over all trials in order.
  double e0 = 0.0, e1 = 1.0, unused0 = 0.0, unused1 = n;
  Extent(position_mm, &unused0, &unused1, &e0, &e1);
  Panel errors(image, {80, 450, 480, 260}, -0.5, n - 0.5, 0.0, e1, "true cutter position error (mm) per goal reached");
  errors.Dots(position_mm, kReachedColour, 3);
  double c1 = 1.0;
  Extent(clearance_cm, &unused0, &unused1, &e0, &c1);
  Extent(tracking_mrad, &unused0, &unused1, &e0, &c1);
  Panel motion(image, {660, 450, 480, 260}, -0.5, n - 0.5, 0.0, c1,
               "per goal: min clearance (cm), tracking error (mrad)");
  motion.Dots(clearance_cm, kClearance, 3);
  motion.Dots(tracking_mrad, kTracking, 3);
  PutText(image, "goal (all trials, in order)", {80, 735}, 0.4, kInk);
  PutText(image, "goal (all trials, in order)", {660, 735}, 0.4, kInk);
  WritePng(path, image);
}

}  // namespace trimbot::scenarios
