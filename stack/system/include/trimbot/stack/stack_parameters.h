#pragma once
// The robot software's parameters, read from robot/config/stack.yaml (every key required, each
// checked: finite, in range, with the file and key named in the error), optionally overridden by
// a section of another file (e.g. a scenario's `stack:`), read by the same rules with every key
// optional.
#include <string>

#include "trimbot/arm/arm_executive.h"
#include "trimbot/common/yaml_reader.h"
#include "trimbot/perception/bush_estimator.h"
#include "trimbot/perception/local_fusion.h"
#include "trimbot/perception/obstacle_points.h"
#include "trimbot/stack/bush_servo.h"
#include "trimbot/stack/ekf.h"
#include "trimbot/stack/navigator.h"
#include "trimbot/stack/obstacle_layer.h"
#include "trimbot/trimming/trim_executive.h"
#include "trimbot/visual_localization/features.h"

namespace trimbot::stack {

enum class LocalizationSource {
  kNone,                // EKF of wheel odometry and gyro only
  kSimulatedPoseFixes,  // PoseFix messages from a test fixture outside the stack
  kVisual,              // the stack's own visual localization against a pre-built map
};

struct VisualLocalizationParameters {
  double rate_hz = 2.0;             // frames localized per second at most
  bool measured_latency = false;    // fixes reach the EKF after the measured processing time, or
  double latency_median = 0.15;     // ... (deterministic mode) after a seeded log-normal latency
  double latency_log_sigma = 0.35;  //     like the real pipeline's (Figure 10 of D3.4)
  double latency_max = 1.5;         // s
  int features = 1000;              // keypoints per camera image
  visual_localization::Descriptor descriptor = visual_localization::Descriptor::kUprightSift;  // the map's too
  bool left_cameras_only = true;    // the left camera of each stereo pair: the robot's SLAM used
                                    // one (grey) camera per pair (D3.4 Section 2.3); all: both
  double image_scale = 0.5;         // resolution the ring is asked for (0.5: 376x240)
  int keyframes = 20;               // retrieved keyframes whose points are matched
  double prior_radius = 3.0;        // m around the EKF's position
  int min_inliers = 30;             // a fix needs this many inliers ...
  double min_inlier_ratio = 0.25;   // ... and this share of its matches (COLMAP's defaults)
  double max_position_sigma = 0.5;  // m: with a larger EKF uncertainty the robot stops
};
const char* ToString(LocalizationSource source);

// Obstacles from stereo: the pairs facing the direction of travel, at rate_hz, into the obstacle
// layer merged with the prior map for navigation.
struct ObstacleDetectionParameters {
  bool enabled = false;
  double rate_hz = 2.5;                     // pair frames per second
  double max_bearing = 0.7;                 // rad: pairs whose optical axis is this close to the direction
                                            // of travel (forward, or backward while backing off)
  int stride = 2;                           // pixel stride of the stereo clouds
  perception::ObstaclePointOptions points;  // the robot's own box comes from the footprint
  ObstacleLayerParameters layer;
};

// The bush approach (goals `approach_bush`): by map to an approach point approach_margin beyond
// the standoff, then by visual servoing on the bush's centre from stereo. The bush is looked for
// at rate_hz with the pair facing it once its mapped centre is within sighting_range.
struct BushApproachParameters {
  double rate_hz = 2.5;          // bush frames per second
  double sighting_range = 3.3;   // m from the arm's axis to the mapped centre
  double approach_margin = 0.4;  // m
  double max_bearing = 0.45;     // rad: the bush must be this close to a pair's optical axis
  perception::BushFitOptions fit;
  BushServoParameters servo;
};

struct StackParameters {
  LocalizationSource localization = LocalizationSource::kNone;
  double initial_position_sigma = 0.2;  // m per axis
  double initial_yaw_sigma = 0.087;     // rad
  EkfParameters ekf;
  double control_rate_hz = 20.0;
  NavigatorParameters navigation;
  perception::LocalFusionOptions local_fusion;
  ObstacleDetectionParameters obstacles;
  BushApproachParameters bush_approach;
  arm::ArmExecutiveParameters arm;  // arm goals: planning, the perceived environment, execution
  // Trim goals: scan, fit, cutting path (its planner, speeds and settling are the arm's).
  trimming::TrimParameters trim;
  VisualLocalizationParameters visual;

  // The trim's parameters with the arm's planner, speeds and settling (one speed model for the
  // arm's goals, the cutting path's costs and the stored paths of trimbot trim precompute).
  trimming::TrimParameters Trim() const;

  // Some component uses the ring's images (the driver must deliver what RingRequestAt asks for).
  bool UsesRingImages() const {
    return localization == LocalizationSource::kVisual || local_fusion.enabled || obstacles.enabled;
  }

  // Reads a complete parameter file. Throws InputError naming the file, line and key.
  static StackParameters Load(const std::string& path);
  // These parameters with the keys present in `section` replaced (unknown keys are errors).
  StackParameters Overridden(const YamlMap& section) const;
};

}  // namespace trimbot::stack
