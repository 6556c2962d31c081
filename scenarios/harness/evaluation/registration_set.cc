#include "evaluation/registration_set.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/random.h"
#include "trimbot/sim/render_pinhole.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {
namespace {

constexpr double kResolutionScale = 0.5;  // 376 x 240: near the Kinect's 320 x 240 depth
constexpr double kLateralPixels = 0.8;    // px, Kinect lateral noise
constexpr int kCamera = 0;                // cam0 looks along base_link's x

// Portable draws (common/random.h) from the set's own stream.
class Draws {
 public:
  Draws(std::uint64_t seed, const std::string& stream) : rng_(MakeRng(seed, stream)) {}
  double Uniform(double lo, double hi) { return lo + (hi - lo) * UniformUnit(rng_); }
  double Normal() { return StandardNormal(rng_); }

 private:
  Rng rng_;
};

// The depth view back-projected into the camera's frame with Kinect-like noise and covariances,
// cropped to the object and the ground around it (options.crop_margin).
perception::PointCloud CloudFromDepth(const cv::Mat& depth, const robot::PinholeRadtan& camera,
                                      const Eigen::Isometry3d& T_map_camera, const garden::GardenObject& object,
                                      const RegistrationSetOptions& options, Draws& draws) {
  const double crop_radius = 0.5 * object.size.head<2>().norm() + options.crop_margin;
  perception::PointCloud cloud;
  for (int v = 0; v < depth.rows; v += options.stride) {
    for (int u = 0; u < depth.cols; u += options.stride) {
      const double z = depth.at<float>(v, u);
      if (z <= 0.0 || z > options.max_depth) continue;
      const Eigen::Vector2d ray = camera.Undistort(Eigen::Vector2d(u, v));
      const double axial = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
      const double lateral = kLateralPixels * z / camera.fx;
      const double noisy_z = z + axial * draws.Normal();
      const double noise_x = draws.Normal(), noise_y = draws.Normal();  // in order, whatever the compiler
      const Eigen::Vector3d point(ray.x() * noisy_z + lateral * noise_x, ray.y() * noisy_z + lateral * noise_y,
                                  noisy_z);
      const Eigen::Vector2d in_map = (T_map_camera * point).head<2>();
      if (options.crop_margin >= 0.0 && (in_map - object.position).norm() > crop_radius) continue;
      cloud.Add(point, Eigen::Vector3d(lateral * lateral, lateral * lateral, axial * axial).asDiagonal());
    }
  }
  return cloud;
}

bool Lookable(const garden::GardenObject& o) {
  using garden::ObjectClass;
  return o.object_class == ObjectClass::kTopiary || o.object_class == ObjectClass::kRose ||
         o.object_class == ObjectClass::kObstacle;
}

// Whether the base standing at `p` would stand clear of every object's footprint.
bool Clear(const garden::Garden& garden, const Eigen::Vector2d& p) {
  for (const auto& o : garden.objects) {
    if (o.base_height > 0.5) continue;  // a crown overhead
    if ((o.position - p).norm() < 0.5 * o.size.head<2>().norm() + 0.5) return false;
  }
  return true;
}

}  // namespace

std::vector<RegistrationPair> RenderRegistrationPairs(const RegistrationSetOptions& options, const ProjectPaths& paths,
                                                      const std::string& work_dir) {
  Setting setting;
  setting.garden = options.garden;
  setting.seed = options.seed;
  sim::SimulatorConfig config = MakeSimulatorConfig(paths, setting, LoadGarden(setting, paths), work_dir + "/world");
  config.render_cameras = true;
  config.cameras_on_schedule = false;
  config.resolution_scale = kResolutionScale;
  sim::Simulator simulator(config);
  std::vector<const garden::GardenObject*> objects;
  for (const auto& o : simulator.garden().objects) {
    if (Lookable(o)) objects.push_back(&o);
  }
  if (objects.empty()) throw InputError(options.garden, "no topiary, rose or obstacle to look at");
  const robot::PinholeRadtan camera = sim::Scaled(simulator.rig().cameras()[kCamera].intrinsics, kResolutionScale);
  // cam0's distance ahead of base_link: the camera stands `distance` from the object's centre.
  const double camera_ahead = simulator.rig().cameras()[kCamera].T_base_camera.translation().x();
  Draws draws(options.seed, "registration_set");
  messages::RingRequest request;
  request.cameras = {kCamera};
  request.resolution_scale = kResolutionScale;

  std::vector<RegistrationPair> pairs;
  for (int attempt = 0; static_cast<int>(pairs.size()) < options.pairs && attempt < 50 * options.pairs; ++attempt) {
    const garden::GardenObject& object = *objects[pairs.size() % objects.size()];
    const double bearing = draws.Uniform(-M_PI, M_PI);
    const double turn_deg = draws.Uniform(options.min_turn_deg, options.max_turn_deg);
    const double turn = turn_deg * M_PI / 180.0 * (draws.Uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0);
    std::array<Pose2, 2> views;
    bool clear = true;
    for (int k = 0; k < 2; ++k) {
      const double b = bearing + k * turn;
      const double distance = draws.Uniform(options.min_distance, options.max_distance) + camera_ahead;
      const Eigen::Vector2d base = object.position + distance * Eigen::Vector2d(std::cos(b), std::sin(b));
      views[static_cast<size_t>(k)] = {base.x(), base.y(), b + M_PI};
      clear = clear && Clear(simulator.garden(), base);
    }
    if (!clear) continue;
    std::array<perception::PointCloud, 2> clouds;
    std::array<Eigen::Isometry3d, 2> T_map_camera;
    for (int k = 0; k < 2; ++k) {
      simulator.PlaceRobot(views[static_cast<size_t>(k)]);
      const sim::RingCapture capture = simulator.CaptureRing(request, true);
      T_map_camera[static_cast<size_t>(k)] = capture.truth.T_map_camera[kCamera];
      clouds[static_cast<size_t>(k)] = CloudFromDepth(capture.truth.views[kCamera].depth, camera,
                                                      T_map_camera[static_cast<size_t>(k)], object, options, draws);
    }
    if (clouds[0].size() < 100 || clouds[1].size() < 100) continue;
    RegistrationPair pair;
    std::ostringstream name;
    name << "render_" << std::setw(3) << std::setfill('0') << pairs.size();
    pair.name = name.str();
    pair.x = std::move(clouds[0]);
    pair.y = std::move(clouds[1]);
    pair.truth = T_map_camera[0].inverse() * T_map_camera[1];  // x = truth * y
    pair.relative_covariances = false;                         // the noise model's variances, m^2
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

}  // namespace trimbot::scenarios
