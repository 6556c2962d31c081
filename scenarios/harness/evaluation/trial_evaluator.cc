#include "evaluation/trial_evaluator.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "evaluation/pose_errors.h"
#include "evaluation/tum_trajectory.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/pose2.h"

namespace trimbot::scenarios {
namespace {

constexpr double kEvaluationPeriod = 0.1;  // s: estimate errors and trajectories at 10 Hz

void AddError(EstimateErrors& errors, double truth_x, double truth_y, double truth_yaw, const Pose2& pose) {
  errors.position_m.push_back(std::hypot(pose.x - truth_x, pose.y - truth_y));
  errors.heading_deg.push_back(std::abs(WrapAngle(pose.yaw - truth_yaw)) * 180.0 / M_PI);
}

std::string Tum(double t, const Pose2& pose) { return TumLine(t, ToIsometry(pose)); }

}  // namespace

std::vector<GoalResult> UnreachedGoals(const std::vector<GoalTruth>& goals) {
  std::vector<GoalResult> results;
  for (const auto& goal : goals) {
    GoalResult result;
    result.x = result.used_x = goal.position.x();
    result.y = result.used_y = goal.position.y();
    result.bush = goal.bush;
    if (goal.yaw) result.yaw_deg = *goal.yaw * 180.0 / M_PI;
    results.push_back(result);
  }
  return results;
}

TrialEvaluator::TrialEvaluator(const std::vector<GoalTruth>& goals, const GoalCriteria& criteria,
                               double fix_history_seconds)
    : truths_(goals),
      criteria_(criteria),
      fix_history_seconds_(fix_history_seconds),
      goals_(UnreachedGoals(goals)),
      bush_status_(goals.size()),
      goal_planned_(goals.size(), false) {}

Eigen::Vector2d TrialEvaluator::TrueBushDistanceBearing(const PlanarPose& truth, int goal) const {
  const Eigen::Vector2d from_arm =
      IntoFrame({truth.x, truth.y, truth.yaw}, truths_[static_cast<std::size_t>(goal)].position) - criteria_.arm_axis;
  return {from_arm.norm(), std::atan2(from_arm.y(), from_arm.x())};
}

void TrialEvaluator::ObserveBushSightings(const StepView& step) {
  for (const stack::BushSighting& sighting : step.telemetry->bush_sightings) {
    const PlanarPose* at = TruthAt(sighting.stamp);
    if (at == nullptr || sighting.goal < 0 || sighting.goal >= static_cast<int>(truths_.size())) continue;
    const Eigen::Vector2d truth = TrueBushDistanceBearing(*at, sighting.goal);
    BushFrame frame;
    frame.t = sighting.stamp;
    frame.goal = sighting.goal;
    frame.true_distance_m = truth.x();
    frame.true_bearing_deg = truth.y() * 180.0 / M_PI;
    frame.found = sighting.found;
    if (sighting.found) {
      frame.distance_error_m = sighting.distance - truth.x();
      frame.bearing_error_deg = WrapAngle(sighting.bearing - truth.y()) * 180.0 / M_PI;
    }
    bush_frames_.push_back(frame);
  }
}

void TrialEvaluator::JudgeBushGoal(const stack::NavigationEvent& event, const PlanarPose& truth,
                                   GoalResult* goal) const {
  const std::optional<stack::BushApproachStatus>& status = bush_status_[static_cast<std::size_t>(event.goal)];
  if (!status) return;  // the stack never reported approaching it: not reached
  const Eigen::Vector2d actual = TrueBushDistanceBearing(truth, event.goal);
  goal->bush_distance_error_m = actual.x() - status->target_distance;
  goal->bush_bearing_error_deg = WrapAngle(actual.y() - status->target_bearing) * 180.0 / M_PI;
  goal->bush_estimate_distance_error_m = status->distance - actual.x();
  goal->bush_estimate_bearing_error_deg = WrapAngle(status->bearing - actual.y()) * 180.0 / M_PI;
  goal->final_error_m = std::abs(goal->bush_distance_error_m);
  goal->reached = std::abs(goal->bush_distance_error_m) <= criteria_.bush_distance &&
                  std::abs(goal->bush_bearing_error_deg) <= criteria_.bush_bearing * 180.0 / M_PI;
  goal->reached_as_asked = goal->reached;  // a bush goal is judged at the bush itself
}

TrialEvaluator::PlanarPose TrialEvaluator::Planar(double t, const Eigen::Isometry3d& pose) {
  const Pose2 planar = ToPose2(pose);
  return {t, planar.x, planar.y, planar.yaw};
}

const TrialEvaluator::PlanarPose* TrialEvaluator::TruthAt(double stamp) const {
  const PlanarPose* best = nullptr;
  for (const auto& p : truth_history_) {
    if (best == nullptr || std::abs(p.t - stamp) < std::abs(best->t - stamp)) best = &p;
  }
  return best != nullptr && std::abs(best->t - stamp) <= timestep_ ? best : nullptr;
}

void TrialEvaluator::Observe(const StepView& step) {
  ++steps_;
  timestep_ = step.timestep;
  const PlanarPose truth = Planar(step.time, step.truth.T_map_base);
  truth_history_.push_back(truth);
  while (truth_history_.size() > 2 && truth_history_.front().t < truth.t - fix_history_seconds_) {
    truth_history_.pop_front();
  }
  // Fixes of the simulated fixture, and the stack's own visual fixes as they reach its EKF.
  std::vector<messages::PoseFix> fixes = step.pose_fixes;
  if (step.telemetry != nullptr) {
    for (const auto& attempt : step.telemetry->visual_attempts) {
      const PlanarPose* at = TruthAt(attempt.stamp);
      const TruePose truth = at != nullptr ? TruePose{at->x, at->y, at->yaw} : TruePose{};
      localization_log_.AddAttempt(attempt, at != nullptr ? &truth : nullptr);
    }
    for (const auto& applied : step.telemetry->visual_fixes) {
      fixes.push_back(applied.fix);
      const PlanarPose* at = TruthAt(applied.fix.stamp);
      const TruePose truth = at != nullptr ? TruePose{at->x, at->y, at->yaw} : TruePose{};
      localization_log_.AddFix(applied, at != nullptr ? &truth : nullptr);
    }
  }
  for (const auto& fix : fixes) {
    fix_stamps_.push_back(fix.stamp);
    fixes_tum_ += Tum(fix.stamp, {fix.x, fix.y, fix.yaw});
    const PlanarPose* at = TruthAt(fix.stamp);
    if (at == nullptr) continue;
    AddError(fixes_, at->x, at->y, at->yaw, {fix.x, fix.y, fix.yaw});
    // Is the fix's stated covariance what its error is? (NEES: 3 on average when it is.)
    const Eigen::Vector3d error(fix.x - at->x, fix.y - at->y, WrapAngle(fix.yaw - at->yaw));
    const double nees = PlanarNees(error, fix.covariance);
    if (std::isfinite(nees)) fixes_.nees.push_back(nees);
  }
  if (have_previous_) path_length_ += std::hypot(truth.x - previous_.x, truth.y - previous_.y);
  previous_ = truth;
  have_previous_ = true;
  ObserveContacts(step);
  if (step.telemetry == nullptr) return;
  if (steps_ % std::lround(kEvaluationPeriod / step.timestep) == 0) Sample(step, truth);
  ObserveBushSightings(step);
  ObserveEvents(step, truth);
  // After the events: a bush goal is judged on the status the stack reported up to its arrival.
  if (const auto& bush = step.telemetry->bush;
      bush && bush->goal >= 0 && bush->goal < static_cast<int>(bush_status_.size())) {
    bush_status_[static_cast<std::size_t>(bush->goal)] = bush;
  }
}

void TrialEvaluator::ObserveContacts(const StepView& step) {
  const bool contact = !step.truth.contacts.empty();
  if (contact && !in_contact_) {
    ++collisions_;
    const int goal = step.telemetry ? step.telemetry->current_goal : 0;
    events_csv_ += std::to_string(step.time) + ",collision," + std::to_string(goal) + "," +
                   step.truth.contacts.front().object_geom + "\n";
  }
  if (contact) contact_seconds_ += step.timestep;
  in_contact_ = contact;
}

void TrialEvaluator::MeasureClearance(const garden::Garden& world, double clearance_height,
                                      const Eigen::Vector2d& outline_min, const Eigen::Vector2d& outline_max) {
  // Boundary points 2 mm apart: a distance to them errs by at most 1 mm.
  constexpr double kSpacing = 0.002;
  footprints_.clear();
  for (const garden::GardenObject& object : world.objects) {
    const double scale = garden::FootprintScaleBelow(object, clearance_height);
    if (scale <= 0.0) continue;
    Footprint footprint;
    footprint.centre = object.position;
    footprint.boundary = garden::FootprintBoundary(object, scale, kSpacing);
    for (const Eigen::Vector2d& p : footprint.boundary) {
      footprint.reach = std::max(footprint.reach, (p - footprint.centre).norm());
    }
    footprints_.push_back(std::move(footprint));
  }
  outline_min_ = outline_min;
  outline_max_ = outline_max;
}

void TrialEvaluator::MeasureClearanceAt(const PlanarPose& truth) {
  // The signed distance of a footprint's boundary point to the outline (a rectangle in base_link):
  // outside, to its nearest edge; inside, minus the way out. A footprint whose every point is
  // farther than the clearance found so far is skipped.
  const Eigen::Vector2d position(truth.x, truth.y);
  const Eigen::Rotation2Dd to_base(-truth.yaw);
  const double outline_reach = outline_min_.cwiseAbs().cwiseMax(outline_max_.cwiseAbs()).norm();
  for (const Footprint& footprint : footprints_) {
    if ((footprint.centre - position).norm() - footprint.reach - outline_reach >= min_clearance_) continue;
    for (const Eigen::Vector2d& point : footprint.boundary) {
      const Eigen::Vector2d q = to_base * (point - position);
      const Eigen::Vector2d outside = (outline_min_ - q).cwiseMax(q - outline_max_);
      const double distance = outside.maxCoeff() > 0.0 ? outside.cwiseMax(0.0).norm() : outside.maxCoeff();
      min_clearance_ = std::min(min_clearance_, distance);
    }
  }
}

void TrialEvaluator::Sample(const StepView& step, const PlanarPose& truth) {
  if (!footprints_.empty()) MeasureClearanceAt(truth);
  const Pose2& estimate = step.telemetry->estimate.pose;
  const Pose2& odometry = step.telemetry->odometry;
  sample_times_.push_back(step.time);
  AddError(ekf_, truth.x, truth.y, truth.yaw, estimate);
  const Eigen::Vector3d error(estimate.x - truth.x, estimate.y - truth.y, WrapAngle(estimate.yaw - truth.yaw));
  const double nees = PlanarNees(error, step.telemetry->estimate.covariance);
  if (std::isfinite(nees)) ekf_.nees.push_back(nees);  // a covariance of zero (an exact start) has none
  AddError(odometry_, truth.x, truth.y, truth.yaw, odometry);
  truth_tum_ += Tum(truth.t, {truth.x, truth.y, truth.yaw});
  ekf_tum_ += Tum(step.time, estimate);
  odometry_tum_ += Tum(step.time, odometry);
}

void TrialEvaluator::ObserveEvents(const StepView& step, const PlanarPose& truth) {
  using Type = stack::NavigationEvent::Type;
  for (const auto& event : step.telemetry->events) {
    std::ostringstream line;
    line << std::fixed << std::setprecision(3) << event.stamp << ',' << stack::ToString(event.type) << ',' << event.goal
         << ',' << event.detail << '\n';
    events_csv_ += line.str();
    if (event.type == Type::kPlanned) {
      ++plans_;
      if (event.goal >= 0 && event.goal < static_cast<int>(goal_planned_.size())) goal_planned_[event.goal] = true;
    }
    if (event.type == Type::kRecovered) ++recoveries_;
    const bool known_goal = event.goal >= 0 && event.goal < static_cast<int>(goals_.size());
    if (event.type == Type::kGoalFailed && known_goal) ++goals_given_up_;
    if (event.type == Type::kGoalReached && known_goal) {
      // Judged where the robot meant to arrive: the asked goal, or where it moved it (reported).
      GoalResult& goal = goals_[event.goal];
      goal.used_x = event.position.x();  // a bush goal: the bush's centre as the stack tracked it
      goal.used_y = event.position.y();
      goal.arrival_time = step.time;
      if (goal.bush != 0) {
        JudgeBushGoal(event, truth, &goal);
        continue;
      }
      goal.adjusted_by_m = std::hypot(goal.used_x - goal.x, goal.used_y - goal.y);
      goal.final_error_m = std::hypot(truth.x - goal.used_x, truth.y - goal.used_y);
      goal.reached = goal.final_error_m <= criteria_.tolerance;
      if (goal.yaw_deg) {
        const double error = WrapAngle(truth.yaw - *goal.yaw_deg * M_PI / 180.0);
        goal.final_heading_error_deg = error * 180.0 / M_PI;
        goal.reached = goal.reached && std::abs(error) <= criteria_.yaw_tolerance;
      }
      goal.reached_as_asked = goal.reached && std::hypot(truth.x - goal.x, truth.y - goal.y) <= criteria_.tolerance;
    }
  }
}

void TrialEvaluator::Finish(bool finished, double time_limit, const stack::Telemetry& telemetry, TrialResult* result) {
  result->goals = goals_;
  if (!finished) {
    result->status = "timeout";
    result->message = "time limit of " + std::to_string(time_limit) + " s reached";
  } else if (telemetry.mission == stack::MissionState::kFailed) {
    result->status = "failed";
    result->message = "navigation gave up goal " + std::to_string(telemetry.current_goal);
  } else {
    result->status = "completed";
  }
  // One plan per goal that got a plan is expected; the others were replans.
  result->replans = plans_ - static_cast<int>(std::count(goal_planned_.begin(), goal_planned_.end(), true));
  result->recoveries = recoveries_;
  result->path_length_m = path_length_;
  result->collisions = collisions_;
  result->contact_seconds = contact_seconds_;
  if (std::isfinite(min_clearance_)) result->min_clearance_m = min_clearance_;
  result->simulated_seconds = telemetry.stamp;
  result->fixes_accepted = telemetry.localization.fixes_accepted;
  result->fixes_rejected = telemetry.localization.fixes_rejected;
  result->relocalizations = telemetry.localization.relocalizations;
  result->estimates = {ekf_, odometry_, fixes_};
  result->bush_frames = bush_frames_;
  result->localization_rate = LocalizationRate();
  result->visual_frames_attempted = telemetry.visual.attempts;
  result->visual_frame_outcomes = localization_log_.Outcomes();
  result->localization_stopped_updates = telemetry.visual.stopped_updates;
  const bool all_reached = std::all_of(goals_.begin(), goals_.end(), [](const GoalResult& g) { return g.reached; });
  result->success = result->status == "completed" && all_reached && collisions_ == 0;
  if (result->status == "completed" && !result->success) {
    result->message = goals_given_up_ > 0 ? "navigation gave up " + std::to_string(goals_given_up_) + " goal(s)"
                      : !all_reached      ? "a goal was declared reached outside the tolerance"
                                          : "collided with the garden";
  }
}

double TrialEvaluator::LocalizationRate() const {
  if (fix_stamps_.empty()) return -1.0;
  std::vector<double> stamps = fix_stamps_;
  std::sort(stamps.begin(), stamps.end());
  int counted = 0, covered = 0;
  for (double t : sample_times_) {
    if (t < stamps.front()) continue;
    ++counted;
    const auto next = std::lower_bound(stamps.begin(), stamps.end(), t - 0.5);
    if (next != stamps.end() && *next <= t + 0.5) ++covered;
  }
  return counted > 0 ? static_cast<double>(covered) / counted : -1.0;
}

void TrialEvaluator::WriteFiles(const std::string& dir) const {
  WriteFileAtomically(dir + "/ground_truth.tum", truth_tum_);
  WriteFileAtomically(dir + "/ekf.tum", ekf_tum_);
  WriteFileAtomically(dir + "/wheel_odometry.tum", odometry_tum_);
  WriteFileAtomically(dir + "/pose_fixes.tum", fixes_tum_);
  if (!localization_log_.empty()) WriteFileAtomically(dir + "/localization.csv", localization_log_.Csv());
  WriteFileAtomically(dir + "/events.csv", events_csv_);
  if (!bush_frames_.empty()) {
    std::ostringstream csv;
    csv << "t,goal,true_distance_m,true_bearing_deg,found,distance_error_m,bearing_error_deg\n" << std::setprecision(6);
    for (const BushFrame& f : bush_frames_) {
      csv << f.t << ',' << f.goal << ',' << f.true_distance_m << ',' << f.true_bearing_deg << ',' << (f.found ? 1 : 0)
          << ',' << f.distance_error_m << ',' << f.bearing_error_deg << '\n';
    }
    WriteFileAtomically(dir + "/bush_frames.csv", csv.str());
  }
}

}  // namespace trimbot::scenarios
