#include "trial.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "output_files.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/garden/garden.h"
#include "trimbot/sim/simulator.h"
#include "trimbot/stack/ekf.h"
#include "trimbot/stack/navigator.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/stack/wheel_odometry.h"

namespace trimbot::scenarios {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kControlPeriod = 0.05;     // s: navigator at 20 Hz
constexpr double kEvaluationPeriod = 0.1;   // s: filter errors and trajectories at 10 Hz

struct PlanarPose {
  double t = 0.0, x = 0.0, y = 0.0, yaw = 0.0;
};

PlanarPose Planar(double t, const Eigen::Isometry3d& pose) {
  const stack::Pose2 planar = stack::ToPose2(pose);
  return {t, planar.x, planar.y, planar.yaw};
}

double AngleDifference(double a, double b) { return std::remainder(a - b, 2.0 * M_PI); }

// Error of an estimate against the ground truth at the same time.
void AddError(EstimateErrors& errors, const PlanarPose& truth, double x, double y, double yaw) {
  errors.position_m.push_back(std::hypot(x - truth.x, y - truth.y));
  errors.heading_deg.push_back(std::abs(AngleDifference(yaw, truth.yaw)) * 180.0 / M_PI);
}

// Ground truth of the last few seconds, to judge late pose fixes at their own stamps.
class TruthHistory {
 public:
  TruthHistory(double seconds, double timestep) : seconds_(seconds), timestep_(timestep) {}
  void Add(const PlanarPose& pose) {
    poses_.push_back(pose);
    while (poses_.size() > 2 && poses_.front().t < pose.t - seconds_) poses_.pop_front();
  }
  // The pose at time t (to within a physics step), or nullptr if it is no longer kept.
  const PlanarPose* At(double t) const {
    const PlanarPose* best = nullptr;
    for (const auto& p : poses_) {
      if (best == nullptr || std::abs(p.t - t) < std::abs(best->t - t)) best = &p;
    }
    return best != nullptr && std::abs(best->t - t) <= timestep_ ? best : nullptr;
  }

 private:
  double seconds_, timestep_;
  std::deque<PlanarPose> poses_;
};

std::string TumLine(const PlanarPose& p) { return scenarios::TumLine(p.t, stack::ToIsometry({p.x, p.y, p.yaw})); }

}  // namespace

TrialResult RunTrial(const TrialSetup& setup, const std::function<void(double)>& progress) {
  const Scenario& scenario = *setup.scenario;
  const auto wall_start = Clock::now();
  std::filesystem::create_directories(setup.dir);

  TrialResult result;
  result.index = setup.index;
  result.seed = setup.seed;
  for (const auto& goal : scenario.goals) result.goals.push_back({goal.x(), goal.y()});
  for (const auto& fault : scenario.faults) result.faults.push_back(fault.Describe());

  sim::SimulatorConfig config = setup.paths.SimulatorConfigFor(scenario.garden, setup.dir + "/world");
  config.seed = setup.seed;
  config.start = scenario.start;
  config.conditions = scenario.conditions;
  config.render_cameras = scenario.render_cameras;
  config.resolution_scale = scenario.resolution_scale;
  config.pose_fixes = scenario.pose_fixes;
  config.faults = scenario.faults;
  config.imu_noise_scale = scenario.imu_noise_scale;
  config.wheel_slip_scale = scenario.wheel_slip_scale;
  sim::Simulator simulator(config);

  // The robot's side: it knows its map, its own geometry and where it was put down.
  const stack::OccupancyGrid map = stack::OccupancyGrid::LoadMapServer(setup.map_yaml);
  const auto& drive = simulator.robot().drive();
  const int ticks_per_revolution = simulator.parameters().wheel_encoders.ticks_per_revolution;
  stack::Ekf ekf(stack::EkfParameters{}, drive, ticks_per_revolution);
  const stack::Pose2 start{scenario.start.x, scenario.start.y, scenario.start.yaw};
  ekf.Initialize(0.0, start, Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, std::pow(2.0 * M_PI / 180.0, 2)).asDiagonal());
  stack::WheelOdometry odometry(drive, ticks_per_revolution);
  stack::NavigatorParameters navigation;
  navigation.follower.cruise_speed = scenario.speed;
  stack::Navigator navigator(map, navigation);
  navigator.SetGoals(scenario.goals);

  EstimateErrors ekf_errors{"ekf", {}, {}}, odometry_errors{"wheel_odometry", {}, {}}, fix_errors{"pose_fixes", {}, {}};
  std::string truth_tum, ekf_tum, odometry_tum, fixes_tum;
  std::string events_csv = "t,event,goal,detail\n";
  TruthHistory truth_history(scenario.pose_fixes.latency_max + 1.0, simulator.timestep());
  PlanarPose previous_truth = Planar(0.0, simulator.ground_truth().T_map_base);
  bool in_contact = false;
  int plans = 0;
  std::vector<bool> goal_planned(scenario.goals.size(), false);
  long step = 0;
  const long control_steps = std::lround(kControlPeriod / simulator.timestep());
  const long evaluation_steps = std::lround(kEvaluationPeriod / simulator.timestep());
  double next_progress = 1.0;

  auto write_outputs = [&]() {
    WriteFileAtomically(setup.dir + "/ground_truth.tum", truth_tum);
    WriteFileAtomically(setup.dir + "/ekf.tum", ekf_tum);
    WriteFileAtomically(setup.dir + "/wheel_odometry.tum", odometry_tum);
    WriteFileAtomically(setup.dir + "/pose_fixes.tum", fixes_tum);
    WriteFileAtomically(setup.dir + "/events.csv", events_csv);
  };

  sim::StepOutputs outputs;
  result.status = "timeout";
  result.message = "time limit of " + std::to_string(scenario.time_limit) + " s reached";
  while (simulator.time() < scenario.time_limit) {
    outputs.Clear();
    simulator.Step(&outputs);
    ++step;
    const double t = simulator.time();

    // Sensor messages into the stack, each at its own rate.
    for (const auto& imu : outputs.imu) ekf.AddImu(imu);
    for (const auto& ticks : outputs.wheel_ticks) {
      ekf.AddWheelTicks(ticks);
      odometry.Update(ticks);
    }
    const PlanarPose truth = Planar(t, simulator.ground_truth().T_map_base);
    truth_history.Add(truth);
    for (const auto& fix : outputs.pose_fixes) {
      ekf.AddPoseFix(fix);
      fixes_tum += TumLine({fix.stamp, fix.x, fix.y, fix.yaw});
      if (const PlanarPose* at = truth_history.At(fix.stamp)) AddError(fix_errors, *at, fix.x, fix.y, fix.yaw);
    }

    // Evaluation: path, contacts, estimate errors.
    result.path_length_m += std::hypot(truth.x - previous_truth.x, truth.y - previous_truth.y);
    previous_truth = truth;
    const std::vector<sim::ObstacleContact> contacts = simulator.ObstacleContacts();
    const bool contact = !contacts.empty();
    if (contact && !in_contact) {
      ++result.collisions;
      events_csv += std::to_string(t) + ",collision," + std::to_string(navigator.current_goal()) + "," +
                    contacts.front().object_geom + "\n";
    }
    if (contact) result.contact_seconds += simulator.timestep();
    in_contact = contact;

    if (step % evaluation_steps == 0) {
      const stack::PoseEstimate estimate = ekf.Estimate();
      const Eigen::Isometry3d odometry_in_map =
          stack::ToIsometry(start) * stack::ToIsometry(odometry.pose());
      const PlanarPose odometry_pose = Planar(t, odometry_in_map);
      AddError(ekf_errors, truth, estimate.pose.x, estimate.pose.y, estimate.pose.yaw);
      AddError(odometry_errors, truth, odometry_pose.x, odometry_pose.y, odometry_pose.yaw);
      truth_tum += TumLine(truth);
      ekf_tum += TumLine({t, estimate.pose.x, estimate.pose.y, estimate.pose.yaw});
      odometry_tum += TumLine(odometry_pose);
    }

    if (step % control_steps == 0) {
      const stack::PoseEstimate estimate = ekf.Estimate();
      simulator.SetBaseCommand(navigator.Update(t, estimate.pose));
      for (const auto& event : navigator.TakeEvents()) {
        std::ostringstream line;
        line << std::fixed << std::setprecision(3) << event.stamp << ',' << stack::ToString(event.type) << ','
             << event.goal << ',' << event.detail << '\n';
        events_csv += line.str();
        using Type = stack::NavigationEvent::Type;
        if (event.type == Type::kPlanned) {
          ++plans;
          goal_planned[event.goal] = true;
        }
        if (event.type == Type::kRecovered) ++result.recoveries;
        if (event.type == Type::kGoalReached) {
          GoalResult& goal = result.goals[event.goal];
          goal.arrival_time = t;
          goal.final_error_m = std::hypot(truth.x - goal.x, truth.y - goal.y);
          goal.reached = goal.final_error_m <= scenario.goal_tolerance;
        }
      }
    }
    if (navigator.mode() == stack::Navigator::Mode::kDone) {
      result.status = "completed";
      result.message.clear();
      break;
    }
    if (navigator.mode() == stack::Navigator::Mode::kFailed) {
      result.status = "failed";
      result.message = "navigation gave up goal " + std::to_string(navigator.current_goal());
      break;
    }
    if (progress && t >= next_progress) {
      progress(t);
      next_progress += 1.0;
    }
  }
  // One plan per goal that got a plan is expected; the others were replans.
  const int goals_planned = static_cast<int>(std::count(goal_planned.begin(), goal_planned.end(), true));
  result.replans = plans - goals_planned;

  result.simulated_seconds = simulator.time();
  const auto& counters = ekf.counters();
  result.fixes_accepted = counters.fixes_accepted;
  result.fixes_rejected = counters.fixes_rejected;
  result.relocalizations = counters.relocalizations;
  result.estimates = {ekf_errors, odometry_errors, fix_errors};
  bool all_reached = true;
  for (const auto& goal : result.goals) all_reached = all_reached && goal.reached;
  result.success = result.status == "completed" && all_reached && result.collisions == 0;
  if (result.status == "completed" && !result.success) {
    result.message = !all_reached ? "a goal was declared reached outside the tolerance" : "collided with the garden";
  }
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  write_outputs();
  WriteFileAtomically(setup.dir + "/result.json", nlohmann::json(result).dump(2));
  return result;
}

}  // namespace trimbot::scenarios
