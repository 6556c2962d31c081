#pragma once
// Plots of the bush approach, after the reference's Figures 17, 18 and 20 (D3.4 Section 2.4).
#include <string>
#include <vector>

#include "evaluation/trial_result.h"

namespace trimbot::scenarios {

// Figure 17: for the first bush goals of the first trial that looked for bushes, the estimated
// distance (arm's axis to the bush's centre) and bearing per frame against the ground truth.
void WriteBushFramePlot(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials);
// Figures 18 and 20: per bush goal of every trial, the mean per-frame error (frames at 1-3 m) and
// the errors at arrival - of the stack's estimate and of the pose reached - with the real
// robot's figures (1.26 cm, 2.08 deg) drawn as reference lines.
void WriteBushErrorPlot(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials);

}  // namespace trimbot::scenarios
