#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "trimbot/visual_localization/features.h"
#include "trimbot/visual_localization/map_builder.h"

namespace trimbot::scenarios {

// What a Kalibr calibration of the ring leaves unknown: each camera's calibration as the stack
// reads it is the true one with these seeded errors (1 sigma), and the cameras' clock is off the
// IMU's by a seeded offset. Defaults: a good Kalibr calibration of MT9V034-class cameras leaves
// 0.1-0.2 px of reprojection error (Kalibr's wiki; issues #103, #502), so each error is sized as
// 0.1 px of its effect: focal length 0.1 of ~550 px, camera-to-camera rotation 0.1 px / 550 px
// (0.01 deg) and translation 0.1 px at a 1 m target (0.2 mm); the principal point's reported
// uncertainty is 0.02-0.2 px; the time offset is estimated to a fraction of the IMU's 5 ms period
// (Furgale, Rehder & Siegwart, IROS 2013). Zeros turn them off. The robot was calibrated once:
// the errors are drawn from `seed` (default 0, the same for every batch and every map), not from
// a trial's seed, so maps built from its log and trials run with it share one calibration.
struct CalibrationError {
  std::uint64_t seed = 0;
  double focal_relative = 2e-4;            // fx, fy scaled by (1 + e): 0.1 px of ~550 px
  double principal_point_px = 0.2;         // cx, cy
  double rotation_deg = 0.01;              // of each camera relative to cam0 (cam0's pose is the URDF's)
  double translation_m = 2e-4;             // of each camera relative to cam0
  double camera_imu_time_offset_s = 5e-4;  // the images' stamps against the IMU's
  bool any() const {
    return focal_relative > 0 || principal_point_px > 0 || rotation_deg > 0 || translation_m > 0 ||
           camera_imu_time_offset_s > 0;
  }
};

// What a map is made from: the mapping drive and the survey. A scenario may name one instead of a
// map file (`visual_map: {mapping_drive: PLAN}`); the map is then built on first use and cached
// (runners/map_cache.h).
struct MapRecipe {
  std::string plan_path;              // the mapping drive: a drive plan, or a scenario with goals
  std::optional<std::uint64_t> seed;  // the drive's (and the survey noise's) seed; default: the plan's
  std::optional<double> seconds;      // stop the drive early
  // From the robot's own log (odometry, loop closure, tie to the surveyed outlines), or from
  // survey poses (truth plus the sigmas below: a laser tracker the user would need).
  visual_localization::KeyframePoses builder = visual_localization::KeyframePoses::kOdometry;
  double survey_position_sigma = 0.02;  // m per axis (surveyed builder)
  double survey_rotation_sigma_deg = 0.5;
  // The calibration the robot's stack reads (the builder's rig) and its clock offset.
  CalibrationError calibration_error;
  // Upright-SIFT or SIFT; default: the stack's (stack.yaml, with the scenario's stack section).
  std::optional<visual_localization::Descriptor> descriptor;
};

}  // namespace trimbot::scenarios
