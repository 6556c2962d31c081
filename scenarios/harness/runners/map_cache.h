#pragma once
// Visual maps built on first use and kept: a scenario that names a mapping drive
// (`visual_map: {mapping_drive: PLAN}`) instead of a map file gets its map from a cache folder,
// keyed by everything the map depends on, so a second run (or every task of a cluster job) reuses
// it and any change of an input builds a new one.
//
// The key (key.txt beside each cached map, one line per input, so `diff` tells why a map was
// rebuilt): the map file's format version, the gardens' appearance version (the texture
// generator's), the mapping drive plan, the garden file, the robot files the rendering and the
// map builder read (URDF, camera calibration, robot parameters), the descriptor, the drive's seed
// and length, the survey noise and the map builder's settings. YAML files enter as their parsed
// content (comments and layout do not count), the URDF as its bytes. A scenario as the mapping
// drive is driven by the stack, so its map also depends on stack.yaml and on the code (a hash of
// the stack's, the simulator's and the trial loop's sources, cmake/SourceFingerprint.cmake); a
// drive plan's map does not. Nothing else: a change of the trials' scenario does not rebuild it.
//
// Cache folder: $TRIMBOT_MAP_CACHE, else $XDG_CACHE_HOME/trimbot/maps, else ~/.cache/trimbot/maps.
// On a cluster it must be a folder every node sees. Builds are serialized by a lock file per key
// (flock), built in a private folder and renamed into place, so concurrent runs build a map once
// and never read a half-written one.
#include <optional>
#include <string>

#include "loop/scenario.h"
#include "loop/setting.h"
#include "runners/mapping.h"

namespace trimbot::scenarios {

std::string DefaultMapCacheDir();

// The key text of a recipe (its descriptor must be set). Throws InputError naming a missing or
// malformed input file.
std::string MapCacheKey(const MapRecipe& recipe, const ProjectPaths& paths);

// Folder name of a key: 16 hex digits of its 64-bit FNV-1a hash (key.txt guards against collisions).
std::string MapCacheId(const std::string& key);

struct CachedMap {
  std::string path;          // map.sqlite
  bool built = false;        // built by this call (else found)
  double build_seconds = 0;  // wall clock of the build (0 when found)
};

// The cached map of `recipe`, built (with progress on stdout) when the cache has none.
CachedMap EnsureCachedMap(const MapRecipe& recipe, const ProjectPaths& paths, const std::string& cache_dir);

// The cached map of `recipe` if the cache has it, else an empty path.
std::string FindCachedMap(const MapRecipe& recipe, const ProjectPaths& paths, const std::string& cache_dir);

// The recipe of the map a scenario builds on first use, with its stack's descriptor (the map is
// made for the localizer that reads it); nullopt when it names a map file or does not localize
// visually.
std::optional<MapRecipe> VisualMapRecipe(const Scenario& scenario, const ProjectPaths& paths);

// A scenario that localizes visually against a mapping drive (visual_map_recipe): its map from the
// cache (built if missing), its visual_map set to the cached file. The recipe's descriptor is the
// scenario's stack's. Nothing for any other scenario. Returns what EnsureCachedMap found or built.
std::optional<CachedMap> ResolveVisualMap(Scenario& scenario, const ProjectPaths& paths,
                                          const std::string& cache_dir = DefaultMapCacheDir());

// `trimbot map ensure`: the map of the scenario at `scenario_path` (with `overrides`) from the
// cache, built if missing; prints which and where. InputError if the scenario builds no map.
int EnsureScenarioMap(const std::string& scenario_path, const std::vector<std::string>& overrides,
                      const ProjectPaths& paths);

}  // namespace trimbot::scenarios
