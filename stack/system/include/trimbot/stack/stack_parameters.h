#pragma once
// The robot software's parameters, read from robot/config/stack.yaml (every key required, each
// checked: finite, in range, with the file and key named in the error), optionally overridden by
// a section of another file (e.g. a scenario's `stack:`), read by the same rules with every key
// optional.
#include <string>

#include "trimbot/common/yaml_reader.h"
#include "trimbot/perception/local_fusion.h"
#include "trimbot/stack/ekf.h"
#include "trimbot/stack/navigator.h"

namespace trimbot::stack {

enum class LocalizationSource {
  kNone,                 // EKF of wheel odometry and gyro only
  kSimulatedPoseFixes,   // PoseFix messages from a test fixture outside the stack
};
const char* ToString(LocalizationSource source);

struct StackParameters {
  LocalizationSource localization = LocalizationSource::kNone;
  double initial_position_sigma = 0.2;  // m per axis
  double initial_yaw_sigma = 0.087;     // rad
  EkfParameters ekf;
  double control_rate_hz = 20.0;
  NavigatorParameters navigation;
  perception::LocalFusionOptions local_fusion;

  // Reads a complete parameter file. Throws InputError naming the file, line and key.
  static StackParameters Load(const std::string& path);
  // These parameters with the keys present in `section` replaced (unknown keys are errors).
  StackParameters Overridden(const YamlMap& section) const;
};

}  // namespace trimbot::stack
