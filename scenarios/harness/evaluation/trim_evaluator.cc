#include "evaluation/trim_evaluator.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "trimbot/common/wall_clock.h"

namespace trimbot::scenarios {
namespace {

// Arm links are checked against the foliage at 50 Hz (every 8th step of 2.5 ms): a link moving
// at the arm's 0.5 m/s at most goes 1 cm between checks, half a leaf clump.
constexpr int kTouchEvery = 8;
constexpr double kTolerance = 0.02;  // m: van Marrewijk et al.'s criterion

}  // namespace

std::vector<int> TrimBushes(const Scenario& scenario) {
  std::vector<int> bushes;
  for (const ScenarioGoal& goal : scenario.goals) {
    if (goal.trim && std::find(bushes.begin(), bushes.end(), goal.bush) == bushes.end()) bushes.push_back(goal.bush);
  }
  return bushes;
}

TrimEvaluator::TrimEvaluator(const sim::Simulator& simulator, const Scenario& scenario)
    : simulator_(simulator), links_(simulator.robot().ArmLinkCylinders()) {
  for (std::size_t g = 0; g < scenario.goals.size(); ++g) {
    const ScenarioGoal& goal = scenario.goals[g];
    if (!goal.cut) continue;
    Trim trim;
    trim.goal = static_cast<int>(g);
    trim.before = *simulator.foliage(goal.bush);
    trim.outcome.goal = trim.goal;
    trim.outcome.bush = goal.bush;
    const garden::CutQuality quality = trim.before.Measure(kTolerance);
    trim.outcome.within_2cm_before = quality.surface_within_tolerance;
    trim.outcome.within_2cm_upper_before = quality.upper_surface_within_tolerance;
    trim.outcome.overgrowth_before_m3 = quality.overgrowth_volume;
    trim.outcome.failure = "not reached: the bush was not approached";
    trims_.push_back(std::move(trim));
  }
}

std::string TrimEvaluator::LinkInFoliage(const sim::GroundTruth& truth, const garden::Foliage& foliage) const {
  const robot::RobotDescription& robot = simulator_.robot();
  std::map<std::string, double> joints;
  const std::vector<std::string> names = robot.ArmJointNames();
  for (std::size_t i = 0; i < names.size(); ++i) joints[names[i]] = truth.arm_position[i];
  for (const robot::LinkCylinder& cylinder : links_) {
    const Eigen::Isometry3d T_map_link = truth.T_map_base * robot.FramePose(cylinder.link, joints);
    if (foliage.ReachesCylinder(T_map_link * cylinder.a, T_map_link * cylinder.b, cylinder.radius)) {
      return cylinder.link;
    }
  }
  return {};
}

void TrimEvaluator::Observe(const StepView& step) {
  ++steps_;
  const stack::Telemetry* telemetry = step.telemetry;
  if (telemetry == nullptr) return;
  for (const stack::TrimResult& result : telemetry->trim_results) Record(result, step.time);
  if (!telemetry->trim) {
    contact_events_.Clear();
    return;
  }
  const auto trim =
      std::find_if(trims_.begin(), trims_.end(), [&](const Trim& t) { return t.goal == telemetry->trim->goal; });
  if (trim == trims_.end()) return;
  if (trim->started < 0.0) {
    trim->started = step.time;
    trim->wall_started = std::chrono::steady_clock::now();
  }
  // The fit is in base_link as it stood for the scan.
  if (telemetry->trim->mode == trimming::ToString(trimming::TrimExecutive::Mode::kWaitingForPoints)) {
    trim->T_map_base = step.truth.T_map_base;
  }
  if (telemetry->trim->mode == trimming::ToString(trimming::TrimExecutive::Mode::kCutting)) {
    trim->outcome.cutting_seconds += step.timestep;
  }
  for (const auto& [arm, other] : contact_events_.Update(step.truth.arm_contacts)) {
    ++trim->outcome.arm_contacts;
    ++trim->outcome.arm_contacts_by[arm + " with " + other + " while " + telemetry->trim->stage];
  }
  if (steps_ % kTouchEvery != 0) return;
  const std::string link = LinkInFoliage(step.truth, *simulator_.foliage(trim->outcome.bush));
  if (!link.empty() && !trim->touching) {
    ++trim->outcome.foliage_touches;
    ++trim->outcome.foliage_touches_by[link + " while " + telemetry->trim->stage];
  }
  trim->touching = !link.empty();
}

void TrimEvaluator::Record(const stack::TrimResult& result, double now) {
  const auto trim = std::find_if(trims_.begin(), trims_.end(), [&](const Trim& t) { return t.goal == result.goal; });
  if (trim == trims_.end()) return;
  const trimming::TrimReport& report = result.report;
  TrimOutcome& o = trim->outcome;
  o.cut = report.cut;
  o.failure = report.failure;
  o.trim_seconds = now - std::max(0.0, trim->started);
  o.points = report.points;
  o.poses = report.poses;
  o.reached_poses = report.reached;
  o.from_database = report.from_database;
  o.path_source = report.path_source;
  o.motion_seconds = report.motion_time;
  o.nearest_neighbour_seconds = report.nearest_neighbour_time;
  o.leaf_depth_m = report.leaf_depth;
  o.moves_round_the_leaves = report.moves_round_the_leaves;
  o.poses_left_out = report.left_out;
  o.poses_unseen = report.unseen;
  o.turns_round_the_leaves = report.turns_round_the_leaves;
  trim->planning_seconds = report.planning_seconds;
  if (trim->started >= 0.0) {
    trim->wall_seconds = SecondsSince(trim->wall_started);
  }
  const garden::Foliage& foliage = *simulator_.foliage(o.bush);
  const garden::CutQuality quality = foliage.Measure(kTolerance);
  o.within_2cm_at_trim_end = quality.surface_within_tolerance;
  o.overcut_share_at_trim_end = quality.target_volume > 0.0 ? quality.overcut_volume / quality.target_volume : 0.0;
  if (!report.fit) return;
  // The fit in base_link, placed where the base truly stood, against the true target.
  const Eigen::Vector3d centre = trim->T_map_base * report.fit->centre;
  const Eigen::Vector3d offset = centre - foliage.pose().translation();
  o.fit_centre_error_m = offset.norm();
  o.fit_centre_offset_m = {offset.x(), offset.y(), offset.z()};
  o.fit_half_m = {report.fit->half.x(), report.fit->half.y(), report.fit->half.z()};
  const Eigen::Vector3d truth = foliage.target().half, fit = report.fit->half;
  const double as_is = std::max(std::abs(fit.x() - truth.x()), std::abs(fit.y() - truth.y()));
  const double swapped = std::max(std::abs(fit.x() - truth.y()), std::abs(fit.y() - truth.x()));
  o.fit_axes_error_max_m = std::max(std::min(as_is, swapped), std::abs(fit.z() - truth.z()));
}

void TrimEvaluator::Finish(TrialResult* result) const {
  bool all = true;
  for (const Trim& trim : trims_) {
    TrimOutcome o = trim.outcome;
    const garden::CutQuality after = simulator_.foliage(o.bush)->Measure(kTolerance);
    o.within_2cm_after = after.surface_within_tolerance;
    o.within_2cm_upper_after = after.upper_surface_within_tolerance;
    o.overgrowth_after_m3 = after.overgrowth_volume;
    o.overcut_share = after.target_volume > 0.0 ? after.overcut_volume / after.target_volume : 0.0;
    o.success = o.cut && o.arm_contacts == 0 && o.foliage_touches == 0;
    all = all && o.success;
    result->trims.push_back(o);
    if (trim.wall_seconds >= 0.0) {
      result->trim_timings.push_back({o.goal, o.bush, o.trim_seconds, trim.wall_seconds, trim.planning_seconds});
    }
  }
  if (!all && result->success) {
    result->success = false;
    if (result->message.empty()) result->message = "a trim failed (see trims)";
  }
}

void TrimEvaluator::WriteFiles(const std::string& dir) const {
  for (const Trim& trim : trims_) {
    const std::string id = std::to_string(trim.outcome.bush);
    trim.before.WritePly(dir + "/foliage_" + id + "_before.ply");
    simulator_.foliage(trim.outcome.bush)->WritePly(dir + "/foliage_" + id + "_after.ply");
  }
}

const garden::Foliage& TrimEvaluator::before(int bush) const {
  for (const Trim& trim : trims_) {
    if (trim.outcome.bush == bush) return trim.before;
  }
  throw std::out_of_range("TrimEvaluator: no trim of bush " + std::to_string(bush));
}

}  // namespace trimbot::scenarios
