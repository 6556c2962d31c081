#pragma once
// Report files of a batch: JUnit XML for CI (one test case per pass criterion, plus one per trial),
// and PNG plots - trajectories over the robot's map (as Figures 13/14 of the reference deliverable)
// histograms of the localization errors (as Figure 12), and where the visual localization broke.
// All files are written atomically.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "evaluation/trial_result.h"
#include "trimbot/garden/garden_tools.h"

namespace trimbot::scenarios {

struct PlotTrajectory {
  int trial = 0;
  bool success = false;
  std::vector<Eigen::Vector2d> ground_truth;  // map frame, metres
  std::vector<Eigen::Vector2d> estimate;      // the EKF's estimate
};

void WriteJunitXml(const std::string& path, const BatchSummary& summary);
// Text for XML or HTML, in elements and attributes: & < > " ' as entities, line breaks and tabs as
// character references, other control characters as '?'.
std::string XmlEscape(const std::string& text);
// `map`: the robot's prior map; `world`: the garden as it really is on the same cells (what the
// map lacks is drawn in its own colour).
void WriteTrajectoryPlot(const std::string& path, const garden::OccupancyMap& map, const garden::OccupancyMap& true_map,
                         const std::vector<PlotTrajectory>& trajectories, const std::vector<Eigen::Vector2d>& goals,
                         const std::string& title);
// One frame the stack's visual localization tried (localization.csv): its true position and outcome.
struct LocalizationFrame {
  Eigen::Vector2d position;  // map frame, metres (NaN when the truth was not known)
  std::string outcome;
};
// Where localization breaks: every frame of the trials at its true position over the map, coloured
// by outcome (fix accepted, no pose, fix rejected by the EKF, re-localization, other), with counts.
void WriteLocalizationMap(const std::string& path, const garden::OccupancyMap& map,
                          const garden::OccupancyMap& true_map, const std::vector<LocalizationFrame>& frames,
                          const std::string& title);
// The frames of a trial's localization.csv; throws InputError naming the file and line when malformed.
std::vector<LocalizationFrame> ReadLocalizationCsv(const std::string& path);
// One panel per estimate name found in the trials (position error in centimetres).
void WriteErrorHistograms(const std::string& path, const std::vector<TrialResult>& trials, const std::string& title);
// x, y of each line of a TUM trajectory file ("t x y z qx qy qz qw"; # comments skipped).
// Throws InputError naming the file and line when it is malformed.
std::vector<Eigen::Vector2d> ReadTumPositions(const std::string& path);

}  // namespace trimbot::scenarios
