#pragma once
// Composes the MuJoCo world (MJCF) of a run: the garden, and the robot (robot_mjcf: from the robot
// description (URDF) and the camera calibration) at its start pose. The MJCF is written next to the
// run's outputs (world/world.xml, which includes world/robot.xml, with its textures), so any run's
// world can be opened and inspected in MuJoCo's viewer.
#include <cstdint>
#include <string>
#include <vector>

#include "trimbot/garden/conditions.h"
#include "trimbot/garden/garden.h"
#include "trimbot/robot/camera_rig.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/sim/robot_mjcf.h"

namespace trimbot::sim {

// $TRIMBOT_TEXTURE_CACHE if set, else trimbot_texture_cache in the system's temporary folder.
std::string DefaultTextureCacheDir();

struct WorldOptions {
  double timestep = 0.002;        // s, fixed physics step
  Pose2 start;                    // base_link in the map frame
  garden::Conditions conditions;  // sun and growth
  int texture_size = 1024;        // px per texture tile
  double render_oversampling = 1.0;
  int msaa_samples = 4;  // multisample anti-aliasing; 0 renders twice as fast, with jagged edges
  // Topiaries the cutter trims (object ids): their leaves give way (drawn, never collided with)
  // and only their wood collides, the target shape kWoodDepth inside (not drawn).
  std::vector<int> cuttable_objects;
  // Generated textures are kept here by (material, garden seed, size, generator version) and
  // copied into each world: every trial of a batch, and every test, uses the same few (seconds
  // to generate and encode). Empty: always generate.
  std::string texture_cache_dir = DefaultTextureCacheDir();
};

// How far inside a trimmed topiary's target its wood begins (m): deeper than the 2 cm a cut may
// go into the target (van Marrewijk et al.'s tolerance), so a blade that keeps to it meets leaves only.
inline constexpr double kWoodDepth = 0.03;

struct WorldSpec {
  std::string mjcf_path;                  // world.xml written to disk (robot.xml beside it)
  std::vector<GeomLabel> labels;          // every named geom that can appear in a label image
  std::vector<std::string> camera_names;  // MuJoCo camera i renders rig camera i
};

WorldSpec ComposeWorld(const robot::RobotDescription& robot, const robot::CameraRig& rig, const garden::Garden& garden,
                       const WorldOptions& options, const std::string& output_dir);

}  // namespace trimbot::sim
