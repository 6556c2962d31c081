#pragma once
// Degrees in files and reports, radians everywhere in the code (REP-103).
#include <cmath>

namespace trimbot {

constexpr double kDegToRad = M_PI / 180.0;

}  // namespace trimbot
