#pragma once
// The arm_reach report: where the cutter poses were (base_link, seen from above and from the side,
// reached or not) and per goal the true position error, the clearance and the tracking error.
#include <string>
#include <vector>

#include "evaluation/trial_result.h"

namespace trimbot::scenarios {

// Nothing is written when no trial has arm goals.
void WriteArmReachPlot(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials);

}  // namespace trimbot::scenarios
