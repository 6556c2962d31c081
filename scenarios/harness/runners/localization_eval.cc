#include "runners/localization_eval.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <sstream>

#include "evaluation/pose_errors.h"
#include "evaluation/trial_result.h"
#include "loop/closed_loop.h"
#include "loop/drive_plan.h"
#include "loop/pilots.h"
#include "loop/prior_knowledge.h"
#include "reports/localization_timing.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/overrides.h"
#include "trimbot/common/pose2.h"
#include "trimbot/common/random.h"
#include "trimbot/robot/robot_files.h"
#include "trimbot/stack/robot_stack.h"
#include "trimbot/visual_localization/localizer.h"

namespace trimbot::scenarios {
namespace {

using visual_localization::Retrieval;
using visual_localization::VisualLocalizer;

constexpr std::uint64_t kQuerySeedOffset = 2000;  // other noise than the plan's own drive (a map's)

struct QueryFrame {
  messages::RingFrame frame;
  Eigen::Isometry3d T_map_base;  // ground truth at the exposure
};

struct QueryDrive {
  Setting setting;
  std::vector<QueryFrame> frames;
};

// Keeps a rendered ring frame every `interval` of simulated time, with its true pose.
class QueryRecorder : public Observer {
 public:
  explicit QueryRecorder(double interval) : interval_(interval) {}
  bool Wants(double stamp) const { return stamp + 1e-9 >= next_; }
  void Observe(const StepView& step) override {
    if (!step.sensors.ring || !Wants(step.sensors.ring->stamp)) return;
    frames_.push_back({*step.sensors.ring, step.truth.T_map_base});
    next_ = step.sensors.ring->stamp + interval_;
  }
  std::vector<QueryFrame>& frames() { return frames_; }

 private:
  double interval_;
  double next_ = 0.0;
  std::vector<QueryFrame> frames_;
};

QueryDrive RenderQueryDrive(const QueryDriveOptions& options, const ProjectPaths& paths, const std::string& work_dir) {
  const DrivePlan plan = DrivePlan::Load(options.plan_path);
  QueryDrive drive;
  drive.setting = plan.setting;
  drive.setting.seed = options.seed.value_or(plan.setting.seed + kQuerySeedOffset);
  if (options.time_of_day) drive.setting.conditions.time_of_day = *options.time_of_day;
  if (options.day_of_year) drive.setting.conditions.day_of_year = *options.day_of_year;
  if (options.growth) drive.setting.conditions.growth = *options.growth;
  drive.setting.start.x -= options.lateral_offset * std::sin(drive.setting.start.yaw);
  drive.setting.start.y += options.lateral_offset * std::cos(drive.setting.start.yaw);
  sim::SimulatorConfig config =
      MakeSimulatorConfig(paths, drive.setting, LoadGarden(drive.setting, paths), work_dir + "/world");
  config.render_cameras = true;
  config.cameras_on_schedule = false;
  config.resolution_scale = *options.resolution_scale;
  config.msaa_samples = options.msaa_samples;
  sim::Simulator simulator(config);
  QueryRecorder recorder(options.interval);
  const double duration = std::min(plan.duration(), options.seconds.value_or(plan.duration()));
  DrivePlanPlayer player(plan, duration);
  LoopOptions loop;
  loop.time_limit = duration;
  loop.render_on_demand = true;
  loop.ring_demand = [&](const sim::GroundTruth& truth) { return recorder.Wants(truth.stamp); };
  std::cout << "[query] rendering ring frames every " << options.interval << " s along " << options.plan_path
            << " (seed " << drive.setting.seed << ", " << drive.setting.conditions.time_of_day << " h, day "
            << drive.setting.conditions.day_of_year << ", growth " << drive.setting.conditions.growth << ")"
            << std::endl;
  RunClosedLoop(simulator, player, {&recorder}, loop);
  drive.frames = std::move(recorder.frames());
  return drive;
}

// The stack's localizer as robot/config/stack.yaml (with the overrides) configures it, and the
// query drive's options with the resolution defaulting to what that localizer asks for.
std::unique_ptr<VisualLocalizer> MakeLocalizer(const LocalizationEvalOptions& options, QueryDriveOptions* drive) {
  const robot::RobotFiles files = options.paths.robot_files();
  stack::StackParameters parameters = stack::StackParameters::Load(files.stack_parameters);
  if (!options.stack_overrides.empty()) {
    YAML::Node root(YAML::NodeType::Map);
    ApplyOverrides(root, ParseOverrides(options.stack_overrides), "--set");
    parameters = parameters.Overridden(YamlMap(root, "--set", ""));
  }
  *drive = options.drive;
  if (!drive->resolution_scale) drive->resolution_scale = parameters.visual.image_scale;
  // The robot's calibration, as `trimbot map build` makes maps with it (loop/map_recipe.h).
  return stack::MakeVisualLocalizer(options.map_path, parameters.visual,
                                    CalibratedRig(robot::LoadCameraRig(files), CalibrationError{}));
}

// The true position plus seeded noise: what the EKF would offer as the retrieval prior.
class NoisyPrior {
 public:
  NoisyPrior(std::uint64_t seed, double sigma) : rng_(MakeRng(seed, "localization_eval_prior")), sigma_(sigma) {}
  Eigen::Vector2d operator()(const Eigen::Isometry3d& truth) {
    return truth.translation().head<2>() + sigma_ * StandardNormalVector<Eigen::Vector2d>(rng_);
  }

 private:
  Rng rng_;
  double sigma_;
};

nlohmann::json DriveJson(const LocalizationEvalOptions& options, const QueryDriveOptions& query,
                         const QueryDrive& drive) {
  return {{"map", options.map_path},
          {"plan", query.plan_path},
          {"seed", drive.setting.seed},
          {"time_of_day", drive.setting.conditions.time_of_day},
          {"day_of_year", drive.setting.conditions.day_of_year},
          {"growth", drive.setting.conditions.growth},
          {"lateral_offset_m", query.lateral_offset},
          {"resolution_scale", *query.resolution_scale},
          {"msaa_samples", query.msaa_samples},
          {"prior_sigma_m", options.prior_sigma},
          {"stack_overrides", options.stack_overrides},
          {"frames", drive.frames.size()}};
}

// The bench's figures, frame by frame: where it was, what came of it, and a fix's error against
// the truth and against the covariance it stated (its NEES: 3 on average when it is what it says,
// as the trials' fixes).
struct BenchTally {
  std::vector<visual_localization::LocalizationTimings> timings;
  std::vector<double> position_errors, heading_errors, nees;
  int fixes = 0, within_25cm = 0;
  std::vector<double> features, matches, inliers;
  std::map<std::string, int> failures;
  std::ostringstream csv{"t,true_x,true_y,true_yaw,fix,failure,features,matches,inliers,error_m,sigma_m,nees\n",
                         std::ios_base::ate};

  void Add(const QueryFrame& query, const visual_localization::LocalizationResult& result) {
    timings.push_back(result.timings);
    features.push_back(result.features);
    matches.push_back(result.matches);
    inliers.push_back(result.inliers);
    const Pose2 truth = ToPose2(query.T_map_base);
    csv << std::fixed << std::setprecision(3) << query.frame.stamp << ',' << truth.x << ',' << truth.y << ','
        << std::setprecision(4) << truth.yaw << ',' << (result.success ? 1 : 0) << ",\"" << result.failure << "\","
        << result.features << ',' << result.matches << ',' << result.inliers << ',';
    if (!result.success) {
      ++failures[result.failure];
      csv << ",,\n";
      return;
    }
    ++fixes;
    const Pose2 fix = ToPose2(result.T_map_base);
    const Eigen::Vector3d error3(fix.x - truth.x, fix.y - truth.y, WrapAngle(fix.yaw - truth.yaw));
    const double error = error3.head<2>().norm();
    position_errors.push_back(error);
    heading_errors.push_back(std::abs(error3.z()) * 180.0 / M_PI);
    within_25cm += error <= 0.25 ? 1 : 0;
    nees.push_back(PlanarNees(error3, result.planar_covariance));
    csv << std::setprecision(4) << error << ',' << LargestPositionSigma(result.planar_covariance) << ','
        << std::setprecision(3) << nees.back() << '\n';
  }
};

// What both evaluations start from: the output folder, the stack's localizer on the map, the
// query drive's rendered frames and the noisy pose prior.
struct QueryEvaluation {
  QueryDriveOptions query;
  std::unique_ptr<VisualLocalizer> localizer;
  QueryDrive drive;
  std::optional<NoisyPrior> prior;

  explicit QueryEvaluation(const LocalizationEvalOptions& options) {
    std::filesystem::create_directories(options.out_dir);
    localizer = MakeLocalizer(options, &query);
    drive = RenderQueryDrive(query, options.paths, options.out_dir);
    prior.emplace(drive.setting.seed, options.prior_sigma);
  }
};

}  // namespace

int RunLocalizationBench(const LocalizationEvalOptions& options) {
  QueryEvaluation evaluation(options);
  const QueryDrive& drive = evaluation.drive;
  BenchTally tally;
  for (const QueryFrame& query : drive.frames) {
    tally.Add(query, evaluation.localizer->Localize(query.frame, (*evaluation.prior)(query.T_map_base)));
  }
  const double n = std::max<double>(1, drive.frames.size());
  const ErrorStats position = ErrorStats::From(tally.position_errors);
  const ErrorStats heading = ErrorStats::From(tally.heading_errors);
  const ErrorStats nees = ErrorStats::From(tally.nees);
  const ErrorStats features = ErrorStats::From(tally.features), matches = ErrorStats::From(tally.matches),
                   inliers = ErrorStats::From(tally.inliers);
  const int fixes = tally.fixes, within_25cm = tally.within_25cm;
  nlohmann::json report = DriveJson(options, evaluation.query, drive);
  report["fix_rate"] = fixes / n;
  report["fixes_within_25cm_rate"] = within_25cm / n;
  report["position_error_m"] = {{"mean", position.mean}, {"median", position.median}, {"max", position.max}};
  report["heading_error_deg"] = {{"mean", heading.mean}, {"median", heading.median}, {"max", heading.max}};
  report["per_frame_median"] = {
      {"features", features.median}, {"matches", matches.median}, {"inliers", inliers.median}};
  report["nees"] = {{"mean", nees.mean}, {"median", nees.median}, {"within_95_rate", NeesWithin95Rate(tally.nees)}};
  report["failures"] = tally.failures;
  report["time"] = LocalizationTimeStats(tally.timings);
  report["threads"] = cv::getNumThreads();
  WriteFileAtomically(options.out_dir + "/localization_bench.json", report.dump(2));
  WriteFileAtomically(options.out_dir + "/localization_frames.csv", tally.csv.str());
  WriteLocalizationTimeHistogram(options.out_dir + "/localization_time.png",
                                 "visual localization time per ring frame (" + std::to_string(drive.frames.size()) +
                                     " frames, " + std::to_string(cv::getNumThreads()) + " threads)",
                                 tally.timings);
  const auto& t = report["time"];
  std::printf(
      "[bench] %zu frames: fixes %.1f %% (within 25 cm %.1f %%), position error mean %.2f / median %.2f cm, "
      "heading %.2f deg\n",
      drive.frames.size(), 100 * fixes / n, 100 * within_25cm / n, 100 * position.mean, 100 * position.median,
      heading.mean);
  std::printf("[bench] fix consistency: NEES mean %.2f, median %.2f, %.1f %% within the 95 %% bound (3 dof)\n",
              nees.mean, nees.median, 100 * report["nees"]["within_95_rate"].get<double>());
  std::printf("[bench] per frame (median): %.0f features, %.0f matches, %.0f inliers\n", features.median,
              matches.median, inliers.median);
  std::printf(
      "[bench] ms per frame, median (p90): features %.1f (%.1f), retrieval %.1f (%.1f), matching %.1f (%.1f), "
      "pose %.1f (%.1f); total %.1f (%.1f), mean %.1f\n",
      t["features"]["median_ms"].get<double>(), t["features"]["p90_ms"].get<double>(),
      t["retrieval"]["median_ms"].get<double>(), t["retrieval"]["p90_ms"].get<double>(),
      t["matching"]["median_ms"].get<double>(), t["matching"]["p90_ms"].get<double>(),
      t["pose"]["median_ms"].get<double>(), t["pose"]["p90_ms"].get<double>(), t["total"]["median_ms"].get<double>(),
      t["total"]["p90_ms"].get<double>(), t["total"]["mean_ms"].get<double>());
  return 0;
}

int RunRetrievalEval(const LocalizationEvalOptions& options) {
  QueryEvaluation evaluation(options);
  const QueryDriveOptions& query = evaluation.query;
  const std::unique_ptr<VisualLocalizer>& localizer = evaluation.localizer;
  const QueryDrive& drive = evaluation.drive;
  NoisyPrior& prior = *evaluation.prior;
  constexpr std::array<int, 3> kThresholds = {50, 100, 200};
  const std::array<std::pair<Retrieval, const char*>, 3> methods = {{{Retrieval::kVocabulary, "vocabulary"},
                                                                     {Retrieval::kPosePrior, "pose_prior"},
                                                                     {Retrieval::kCombined, "combined"}}};
  // Per method: counts of (query image, keyframe) and (query rig, keyframe) pairs at each threshold.
  std::array<std::array<int, 3>, 3> image_hits{}, rig_hits{};
  std::array<int, 3> image_pairs{}, rig_pairs{};
  const int cameras = static_cast<int>(localizer->T_base_camera().size());
  for (const QueryFrame& query : drive.frames) {
    VisualLocalizer::FrameFeatures features = localizer->Extract(query.frame);
    localizer->AssignWords(&features);
    const Eigen::Vector2d position = prior(query.T_map_base);
    std::vector<int> cameras_seen;
    for (int c : features.camera) {
      if (cameras_seen.empty() || cameras_seen.back() != c) cameras_seen.push_back(c);
    }
    for (std::size_t m = 0; m < methods.size(); ++m) {
      for (int keyframe : localizer->Retrieve(features, position, methods[m].first, options.retrieval_top)) {
        // Geometrically verified: inliers of the ring's pose from this keyframe's points alone.
        const auto correspondences = localizer->Match(features, {keyframe});
        const auto pose = visual_localization::EstimateRigPose(correspondences, localizer->T_base_camera(),
                                                               localizer->options().pose);
        std::vector<int> per_camera(static_cast<std::size_t>(cameras), 0);
        if (pose.success) {
          for (int i : pose.inliers)
            ++per_camera[static_cast<std::size_t>(correspondences[static_cast<std::size_t>(i)].camera)];
        }
        const int total = pose.success ? static_cast<int>(pose.inliers.size()) : 0;
        ++rig_pairs[m];
        image_pairs[m] += static_cast<int>(cameras_seen.size());
        for (std::size_t k = 0; k < kThresholds.size(); ++k) {
          rig_hits[m][k] += total >= kThresholds[k] ? 1 : 0;
          for (int c : cameras_seen)
            image_hits[m][k] += per_camera[static_cast<std::size_t>(c)] >= kThresholds[k] ? 1 : 0;
        }
      }
    }
  }
  nlohmann::json report = DriveJson(options, query, drive);
  std::printf("%-12s %28s   %28s\n", "retrieval", "single image [%]", "generalized image (rig) [%]");
  std::printf("%-12s %8s %9s %9s   %8s %9s %9s\n", "", ">= 50", ">= 100", ">= 200", ">= 50", ">= 100", ">= 200");
  for (std::size_t m = 0; m < methods.size(); ++m) {
    nlohmann::json row = {{"retrieved_keyframes", rig_pairs[m]}, {"image_pairs", image_pairs[m]}};
    std::array<double, 6> shares{};
    for (std::size_t k = 0; k < kThresholds.size(); ++k) {
      shares[k] = 100.0 * image_hits[m][k] / std::max(1, image_pairs[m]);
      shares[3 + k] = 100.0 * rig_hits[m][k] / std::max(1, rig_pairs[m]);
      row["single_image_percent"][">=" + std::to_string(kThresholds[k])] = shares[k];
      row["rig_percent"][">=" + std::to_string(kThresholds[k])] = shares[3 + k];
    }
    report["methods"][methods[m].second] = row;
    std::printf("%-12s %8.2f %9.2f %9.2f   %8.2f %9.2f %9.2f\n", methods[m].second, shares[0], shares[1], shares[2],
                shares[3], shares[4], shares[5]);
  }
  WriteFileAtomically(options.out_dir + "/retrieval_eval.json", report.dump(2));
  return 0;
}

}  // namespace trimbot::scenarios
