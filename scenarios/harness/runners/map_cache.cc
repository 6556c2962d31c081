#include "runners/map_cache.h"

#include "mapping_run_sources.h"  // generated: TRIMBOT_MAPPING_RUN_SOURCES

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "loop/prior_knowledge.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/random.h"
#include "trimbot/common/yaml_reader.h"
#include "trimbot/garden/textures.h"
#include "trimbot/visual_localization/map_builder.h"
#include "trimbot/visual_localization/visual_map.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;

std::string Hex(std::uint64_t value) {
  std::ostringstream out;
  out << std::hex << std::setw(16) << std::setfill('0') << value;
  return out.str();
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "file not found");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A YAML file's content as the readers see it: parsed and emitted again, so comments and layout
// do not change the key.
std::string YamlContent(const std::string& path) {
  YAML::Emitter emitter;
  emitter << YamlMap::LoadFile(path).node();
  return emitter.c_str();
}

std::string Number(double value) {
  std::ostringstream out;
  out << std::setprecision(17) << value;
  return out.str();
}

// Every setting of the map builder, so that a changed default rebuilds the maps made with it.
std::string BuilderSettings(const visual_localization::MapBuilderOptions& o) {
  std::ostringstream out;
  const visual_localization::OdometryFactorOptions& d = o.odometry;
  const visual_localization::LoopClosureOptions& l = o.loops;
  out << "builder " << visual_localization::ToString(o.poses) << "\n"
      << "descriptor " << visual_localization::ToString(o.features.descriptor) << "\n"
      << "max_features " << o.features.max_features << "\n"
      << "keyframe_distance " << Number(o.keyframe_distance) << "\nkeyframe_angle " << Number(o.keyframe_angle) << "\n"
      << "match_next_keyframes " << o.match_next_keyframes << "\nmax_camera_angle " << Number(o.max_camera_angle)
      << "\n"
      << "ratio " << Number(o.ratio) << "\nepipolar_angle " << Number(o.epipolar_angle) << "\n"
      << "survey_position_sigma " << Number(o.survey_position_sigma) << "\n"
      << "survey_rotation_sigma " << Number(o.survey_rotation_sigma) << "\n"
      << "pixel_sigma " << Number(o.pixel_sigma) << "\nmax_reprojection_error " << Number(o.max_reprojection_error)
      << "\n"
      << "min_triangulation_angle " << Number(o.min_triangulation_angle) << "\nmax_depth " << Number(o.max_depth)
      << "\n"
      << "vocabulary_words " << o.vocabulary_words << "\nadjustment_iterations " << o.adjustment_iterations << "\n";
  if (o.poses == visual_localization::KeyframePoses::kOdometry) {
    out << "odometry_epipolar_angle " << Number(o.odometry_epipolar_angle) << "\nodometry " << Number(d.along_sigma)
        << " " << Number(d.along_sigma_per_m) << " " << Number(d.lateral_sigma) << " " << Number(d.lateral_sigma_per_m)
        << " " << Number(d.yaw_sigma) << " " << Number(d.yaw_sigma_per_rad) << " " << Number(d.height_sigma) << " "
        << Number(d.tilt_sigma) << " " << Number(d.scale_stretch) << " " << Number(d.scale_prior_sigma) << " "
        << Number(d.scale_change_sigma) << "\nloops " << Number(l.min_travel) << " " << Number(l.search_radius) << " "
        << Number(l.search_radius_per_m) << " " << l.candidates << " " << l.min_inliers << " "
        << Number(l.position_sigma) << " " << Number(l.rotation_sigma) << " " << Number(l.loss_scale) << "\ntie "
        << Number(o.tie.min_height) << " " << Number(o.tie.start_distance) << " " << Number(o.tie.end_distance) << " "
        << Number(o.tie.huber) << " " << o.tie.iterations << "\n";
  }
  return out.str();
}

// Holds an exclusive lock on a file for its lifetime (released by the kernel if the process dies).
class FileLock {
 public:
  explicit FileLock(const std::string& path) : fd_(open(path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644)) {
    if (fd_ < 0) throw InputError(path, "cannot create the map cache's lock file (is the cache folder writable?)");
    while (flock(fd_, LOCK_EX) != 0) {
      if (errno != EINTR) throw InputError(path, "cannot lock the map cache");
    }
  }
  ~FileLock() { close(fd_); }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_;
};

bool Holds(const std::string& folder, const std::string& key) {
  if (!fs::exists(folder + "/map.sqlite") || !fs::exists(folder + "/key.txt")) return false;
  return ReadBytes(folder + "/key.txt") == key;
}

// Builds the map in a child process: the build starts thread pools (OpenCV, Ceres, OpenMP) that
// would stay in this process, and a batch forks its trials after it - a child forked while another
// thread holds a lock inside such a pool deadlocks. A failure is rethrown here with the child's
// message; nothing half-built stays in the cache.
void BuildInChildProcess(const MapBuildOptions& build) {
  fs::create_directories(build.out_dir);
  const std::string error_file = build.out_dir + "/error.txt";
  std::cout.flush();
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed: " + std::string(std::strerror(errno)));
  if (pid == 0) {
    int code = 0;
    try {
      RunMapBuild(build);
    } catch (const InputError& e) {
      std::ofstream(error_file) << "input\n" << e.file() << "\n" << e.problem();
      code = 2;
    } catch (const std::exception& e) {
      std::ofstream(error_file) << "internal\n\n" << e.what();
      code = 3;
    }
    std::fflush(nullptr);
    _exit(code);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("waitpid failed: " + std::string(std::strerror(errno)));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  std::ifstream in(error_file);
  std::string kind, file, message;
  std::getline(in, kind);
  std::getline(in, file);
  message.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  fs::remove_all(build.out_dir);
  if (kind == "input") throw InputError(file, message);
  if (message.empty()) {
    message = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                  : "exited with code " + std::to_string(WEXITSTATUS(status));
  }
  throw std::runtime_error("building the map of " + build.recipe.plan_path + ": " + message);
}

}  // namespace

std::string DefaultMapCacheDir() {
  if (const char* dir = std::getenv("TRIMBOT_MAP_CACHE"); dir != nullptr && *dir != '\0') return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg != '\0')
    return std::string(xdg) + "/trimbot/maps";
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0')
    return std::string(home) + "/.cache/trimbot/maps";
  return (fs::temp_directory_path() / "trimbot_maps").string();
}

std::string MapCacheKey(const MapRecipe& recipe, const ProjectPaths& paths) {
  if (!recipe.descriptor) throw std::logic_error("MapCacheKey: the recipe's descriptor is not set");
  const YamlMap plan = YamlMap::LoadFile(recipe.plan_path);
  const Setting setting = Setting::Read(plan, /*with_seed=*/false);
  const robot::RobotFiles robot = paths.robot_files();
  std::ostringstream key;
  key << "trimbot visual map cache key 1\n"
      << "map format version " << visual_localization::kMapFormatVersion << "\n"
      << "map builder version " << visual_localization::kMapBuilderVersion << "\n"
      << "garden appearance version " << garden::kTextureGeneratorVersion << "\n"
      << "mapping drive " << Hex(Fnv1a(YamlContent(recipe.plan_path))) << "\n"
      << "garden " << Hex(Fnv1a(YamlContent(ResolveGarden(setting, paths)))) << "\n"
      << "urdf " << Hex(Fnv1a(ReadBytes(robot.urdf))) << "\n"
      << "camchain " << Hex(Fnv1a(YamlContent(robot.camchain))) << "\n"
      << "robot parameters " << Hex(Fnv1a(YamlContent(robot.robot_parameters))) << "\n";
  const CalibrationError& c = recipe.calibration_error;
  key << "calibration error " << Number(c.focal_relative) << " " << Number(c.principal_point_px) << " "
      << Number(c.rotation_deg) << " " << Number(c.translation_m) << " " << Number(c.camera_imu_time_offset_s)
      << " seed " << c.seed << "\n";
  // The log builder's odometry runs the stack's EKF (its gyro bias).
  if (recipe.builder == visual_localization::KeyframePoses::kOdometry) {
    const stack::EkfParameters e = stack::StackParameters::Load(robot.stack_parameters).ekf;
    key << "odometry ekf " << Number(e.linear_acceleration_density) << " " << Number(e.angular_acceleration_density)
        << " " << Number(e.gyro_bias_random_walk) << " " << Number(e.wheel_speed_sigma) << " "
        << Number(e.wheel_slip_fraction) << " " << Number(e.wheel_scale_sigma) << " "
        << Number(e.wheel_scale_random_walk) << " " << Number(e.gyro_sigma) << "\n";
  }
  // A scenario as the mapping drive is driven by the stack: all of its parameters count then, and
  // its code (where the drive goes, and so the map, changes with the planner or the simulator).
  if (plan.Has("goals")) {
    key << "stack parameters " << Hex(Fnv1a(YamlContent(robot.stack_parameters))) << "\n"
        << "mapping run sources " << TRIMBOT_MAPPING_RUN_SOURCES << "\n";
  }
  key << "seed " << (recipe.seed ? std::to_string(*recipe.seed) : "the plan's") << "\n"
      << "seconds " << (recipe.seconds ? Number(*recipe.seconds) : "the whole drive") << "\n"
      << BuilderSettings(MapBuilderOptionsFor(recipe, *recipe.descriptor));
  return key.str();
}

std::string MapCacheId(const std::string& key) { return Hex(Fnv1a(key)); }

std::string FindCachedMap(const MapRecipe& recipe, const ProjectPaths& paths, const std::string& cache_dir) {
  const std::string key = MapCacheKey(recipe, paths);
  const std::string folder = cache_dir + "/" + MapCacheId(key);
  return Holds(folder, key) ? folder + "/map.sqlite" : "";
}

CachedMap EnsureCachedMap(const MapRecipe& recipe, const ProjectPaths& paths, const std::string& cache_dir) {
  const std::string key = MapCacheKey(recipe, paths);
  const std::string id = MapCacheId(key);
  const std::string folder = cache_dir + "/" + id;
  CachedMap cached{folder + "/map.sqlite", false, 0.0};
  if (Holds(folder, key)) return cached;
  std::error_code error;
  fs::create_directories(cache_dir, error);
  if (error) throw InputError(cache_dir, "cannot create the map cache folder: " + error.message());
  const FileLock lock(cache_dir + "/" + id + ".lock");
  if (Holds(folder, key)) return cached;  // another process built it while we waited

  const auto start = std::chrono::steady_clock::now();
  std::cout << "[map] no cached map of " << recipe.plan_path << " (key " << id << "): building it once into " << folder
            << std::endl;
  const std::string staging = folder + ".building-" + std::to_string(getpid());
  fs::remove_all(staging);
  BuildInChildProcess(MapBuildOptions{recipe, staging, paths});
  // The composed world and the mapping drive's prior map are scratch; the map and its report stay.
  fs::remove_all(staging + "/world");
  fs::remove_all(staging + "/prior_map");
  WriteFileAtomically(staging + "/key.txt", key);
  fs::remove_all(folder);  // a map of the same id with another key (a hash collision) or a broken one
  fs::rename(staging, folder);
  cached.built = true;
  cached.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return cached;
}

std::optional<MapRecipe> VisualMapRecipe(const Scenario& scenario, const ProjectPaths& paths) {
  if (!scenario.visual_map_recipe) return std::nullopt;
  const stack::StackParameters parameters = StackParametersFor(scenario, paths);
  if (parameters.localization != stack::LocalizationSource::kVisual) return std::nullopt;
  MapRecipe recipe = *scenario.visual_map_recipe;
  recipe.descriptor = parameters.visual.descriptor;  // the map is made for the localizer that reads it
  return recipe;
}

std::optional<CachedMap> ResolveVisualMap(Scenario& scenario, const ProjectPaths& paths, const std::string& cache_dir) {
  const std::optional<MapRecipe> recipe = VisualMapRecipe(scenario, paths);
  if (!recipe) {
    // A map file the scenario names must show the garden as this build renders it.
    if (!scenario.visual_map.empty() &&
        StackParametersFor(scenario, paths).localization == stack::LocalizationSource::kVisual) {
      const int version = visual_localization::VisualMap::Load(scenario.visual_map).appearance_version;
      if (version != garden::kTextureGeneratorVersion) {
        throw InputError(scenario.visual_map, "the map shows the garden's appearance version " +
                                                  std::to_string(version) + ", this build renders version " +
                                                  std::to_string(garden::kTextureGeneratorVersion) +
                                                  " (rebuild the map with `trimbot map build`)");
      }
    }
    return std::nullopt;
  }
  CachedMap map = EnsureCachedMap(*recipe, paths, cache_dir);
  scenario.visual_map = map.path;
  return map;
}

int EnsureScenarioMap(const std::string& scenario_path, const std::vector<std::string>& overrides,
                      const ProjectPaths& paths) {
  Scenario scenario = Scenario::Load(scenario_path, ParseOverrides(overrides));
  const auto map = ResolveVisualMap(scenario, paths);
  if (!map) {
    throw InputError(scenario_path,
                     "key 'visual_map': the scenario builds no map (it names a map file, or does not "
                     "localize visually)");
  }
  std::cout << "[map] " << (map->built ? "built" : "cached") << ": " << map->path << std::endl;
  return 0;
}

}  // namespace trimbot::scenarios
