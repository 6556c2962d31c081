#include "evaluation/arm_reach.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/random.h"

namespace trimbot::scenarios {
namespace {

constexpr double kWorldRadius = 2.5;     // m around the base: the garden the arm could touch
constexpr long kMaxSamples = 400000;     // joint configurations drawn before giving up
constexpr double kDistinctPoses = 0.03;  // m between the cutter tips of two poses

Eigen::VectorXd JointVector(const std::array<double, messages::kArmJoints>& q) {
  return Eigen::Map<const Eigen::VectorXd>(q.data(), static_cast<int>(q.size()));
}

// The arm against itself and the robot: contact only (the wrist's links are always a few cm apart).
robot::CollisionCheckOptions SelfOnly() {
  robot::CollisionCheckOptions options;
  options.environment = false;
  return options;
}

// The arm against the garden and the ground, with the clearance.
robot::CollisionCheckOptions EnvironmentClearance() {
  robot::CollisionCheckOptions options;
  options.self = false;
  options.distance = true;
  return options;
}

}  // namespace

ArmCollisionTruth MakeArmCollisionTruth(const Scenario& scenario, const sim::Simulator& simulator,
                                        const Eigen::Isometry3d& T_map_base) {
  const ArmReach& spec = *scenario.arm_reach;
  ArmCollisionTruth truth{
      robot::CollisionModel(simulator.robot(), simulator.robot().ArmJointNames()), {}, {}, simulator.garden().name};
  const auto& objects = simulator.garden().objects;
  const auto bush =
      std::find_if(objects.begin(), objects.end(), [&](const garden::GardenObject& o) { return o.id == spec.bush; });
  const std::string what = "arm_reach: bush " + std::to_string(spec.bush) + ": ";
  if (bush == objects.end())
    throw InputError(scenario.source, what + "the garden has no object " + std::to_string(spec.bush));
  if (bush->object_class != garden::ObjectClass::kTopiary && bush->object_class != garden::ObjectClass::kRose) {
    throw InputError(scenario.source, what + "object " + std::to_string(spec.bush) + " is a " +
                                          garden::ToString(bush->object_class) + ", not a bush (topiary or rose)");
  }
  truth.bush_centre << bush->position, bush->base_height + 0.5 * bush->size.z();
  for (const sim::CollisionHull& hull : simulator.GardenCollisionHulls()) {
    const bool near = std::any_of(hull.vertices.begin(), hull.vertices.end(), [&](const Eigen::Vector3d& v) {
      return (v.head<2>() - T_map_base.translation().head<2>()).norm() < kWorldRadius;
    });
    if (!near) continue;
    if (hull.object_id == spec.bush) truth.bush.push_back(truth.model.environment().size());
    truth.model.environment().AddConvex(hull.geom, hull.vertices, hull.triangles);
  }
  if (truth.bush.empty()) {
    throw InputError(scenario.source, what + "the bush is farther than " + std::to_string(kWorldRadius) +
                                          " m from the start: out of the arm's reach");
  }
  truth.model.environment().AddGround("ground", 0.0);
  return truth;
}

std::vector<ArmReachPose> GenerateArmReachPoses(const Scenario& scenario, const ArmCollisionTruth& truth,
                                                const robot::RobotDescription& robot,
                                                const Eigen::Isometry3d& T_map_base, std::uint64_t seed) {
  const ArmReach& spec = *scenario.arm_reach;
  // Each garden and bush its own stream: with the same seed, two bushes of a similar size would
  // otherwise share the poses both accept.
  Rng rng = MakeRng(seed, "arm_reach_poses/" + truth.garden + "/" + std::to_string(spec.bush));
  const auto uniform = [&rng]() { return UniformUnit(rng); };
  const std::vector<std::string> names = robot.ArmJointNames();
  std::vector<ArmReachPose> poses;
  long samples = 0;
  for (; samples < kMaxSamples && static_cast<int>(poses.size()) < spec.poses; ++samples) {
    Eigen::VectorXd q(static_cast<int>(names.size()));
    std::map<std::string, double> joints;
    for (size_t i = 0; i < names.size(); ++i) {
      const urdf::Joint& joint = *robot.urdf().getJoint(names[i]);
      const double u = uniform();
      q(static_cast<int>(i)) = joint.type == urdf::Joint::REVOLUTE
                                   ? joint.limits->lower + (joint.limits->upper - joint.limits->lower) * u
                                   : -M_PI + 2.0 * M_PI * u;
      joints[names[i]] = q(static_cast<int>(i));
    }
    // Cheap tests first: the tip near the bush and the cutter facing it, then the exact ones.
    const Eigen::Isometry3d T_base_cutter = robot.FramePose(robot::RobotFrames::kEndEffector, joints);
    const Eigen::Isometry3d T_map_cutter = T_map_base * T_base_cutter;
    const Eigen::Vector3d tip = T_map_cutter.translation();
    const Eigen::Vector3d to_centre = truth.bush_centre - tip;
    if (to_centre.norm() > 1.5) continue;
    if (std::acos(std::clamp(T_map_cutter.linear().col(2).dot(to_centre.normalized()), -1.0, 1.0)) > spec.max_tilt)
      continue;
    double surface = 1e9;
    for (int index : truth.bush) surface = std::min(surface, truth.model.environment().DistanceTo(index, tip));
    if (surface < spec.distance_min || surface > spec.distance_max) continue;
    const bool distinct = std::none_of(poses.begin(), poses.end(), [&](const ArmReachPose& p) {
      return (p.cutter_base.translation() - T_base_cutter.translation()).norm() < kDistinctPoses;
    });
    if (!distinct) continue;
    if (truth.model.Check(q, SelfOnly(), T_map_base).collision) continue;
    const robot::CollisionReport report = truth.model.Check(q, EnvironmentClearance(), T_map_base);
    if (report.collision || report.clearance < spec.min_clearance) continue;
    poses.push_back({T_base_cutter, q, report.clearance, surface});
  }
  if (static_cast<int>(poses.size()) < spec.poses) {
    throw InputError(scenario.source, "arm_reach: only " + std::to_string(poses.size()) + " of " +
                                          std::to_string(spec.poses) + " cutter poses found in " +
                                          std::to_string(samples) +
                                          " random joint configurations: is the bush within the arm's reach?");
  }
  return poses;
}

ArmReachEvaluator::ArmReachEvaluator(const ArmReach& spec, std::vector<ArmReachPose> poses, ArmCollisionTruth* truth,
                                     std::function<void(int)> on_reached)
    : spec_(spec), poses_(std::move(poses)), truth_(truth), on_reached_(std::move(on_reached)) {
  for (size_t i = 0; i < poses_.size(); ++i) {
    ArmGoalOutcome outcome;
    outcome.goal = static_cast<int>(i);
    const Eigen::Vector3d& p = poses_[i].cutter_base.translation();
    outcome.x = p.x();
    outcome.y = p.y();
    outcome.z = p.z();
    outcome.witness_clearance_m = poses_[i].witness_clearance;
    outcomes_.push_back(outcome);
  }
}

void ArmReachEvaluator::Observe(const StepView& step) {
  const sim::GroundTruth& truth = step.truth;
  const bool working = current_ < static_cast<int>(outcomes_.size());
  const int events = static_cast<int>(contact_events_.Update(truth.arm_contacts).size());
  contacts_ += events;
  if (working) outcomes_[static_cast<size_t>(current_)].contacts += events;

  const Eigen::VectorXd q = JointVector(truth.arm_position);
  const stack::Telemetry* telemetry = step.telemetry;
  if (telemetry != nullptr && telemetry->arm) {
    current_ = telemetry->arm->goal;
    const std::vector<double>& target = telemetry->arm->target;
    if (current_ < static_cast<int>(outcomes_.size()) && target.size() == static_cast<size_t>(q.size())) {
      ArmGoalOutcome& outcome = outcomes_[static_cast<size_t>(current_)];
      const double error = (q - Eigen::Map<const Eigen::VectorXd>(target.data(), q.size())).cwiseAbs().maxCoeff();
      outcome.tracking_error_max_rad = std::max(outcome.tracking_error_max_rad, error);
    }
  }
  // The true clearance, at about 20 Hz while a goal is worked on.
  const long every = std::max(1L, std::lround(0.05 / std::max(step.timestep, 1e-6)));
  if (current_ < static_cast<int>(outcomes_.size()) && steps_++ % every == 0) {
    const double clearance = truth_->model.Check(q, EnvironmentClearance(), truth.T_map_base).clearance;
    ArmGoalOutcome& outcome = outcomes_[static_cast<size_t>(current_)];
    outcome.min_clearance_m = outcome.min_clearance_m < 0.0 ? clearance : std::min(outcome.min_clearance_m, clearance);
  }
  if (telemetry == nullptr) return;
  for (const arm::ArmGoalResult& reported : telemetry->arm_results) {
    if (reported.goal < 0 || reported.goal >= static_cast<int>(outcomes_.size())) continue;
    ArmGoalOutcome& outcome = outcomes_[static_cast<size_t>(reported.goal)];
    outcome.stack_reached = reported.reached;
    outcome.failure = reported.failure;
    outcome.ik_solutions = reported.ik_solutions;
    outcome.free_goals = reported.free_goals;
    outcome.path_length_rad = reported.path_length;
    outcome.cutter_path_length_m = reported.cutter_path_length;
    outcome.motion_seconds = reported.motion_duration;
    planning_seconds_.push_back(reported.planning_seconds);
    // The cutter where it truly is, in base_link (the base settles on its wheels: not the arm's error).
    const Eigen::Isometry3d T_base_cutter = truth.T_map_base.inverse() * truth.T_map_end_effector;
    const Eigen::Isometry3d& goal = poses_[static_cast<size_t>(reported.goal)].cutter_base;
    outcome.position_error_m = (T_base_cutter.translation() - goal.translation()).norm();
    outcome.orientation_error_deg =
        Eigen::AngleAxisd(T_base_cutter.linear().transpose() * goal.linear()).angle() * 180.0 / M_PI;
    if (reported.reached && on_reached_) on_reached_(reported.goal);
  }
}

void ArmReachEvaluator::Finish(TrialResult* result) const {
  result->arm_goals = outcomes_;
  for (ArmGoalOutcome& outcome : result->arm_goals) {
    outcome.reached = outcome.stack_reached && outcome.contacts == 0 &&
                      outcome.position_error_m <= spec_.position_tolerance &&
                      outcome.orientation_error_deg <= spec_.orientation_tolerance * 180.0 / M_PI;
  }
  result->arm_contacts = contacts_;
  result->arm_planning_seconds = planning_seconds_;
  const int reached = static_cast<int>(std::count_if(result->arm_goals.begin(), result->arm_goals.end(),
                                                     [](const ArmGoalOutcome& g) { return g.reached; }));
  result->success = result->status == "completed" && reached == static_cast<int>(outcomes_.size()) && contacts_ == 0;
  if (result->status == "completed" && !result->success) {
    result->message = std::to_string(static_cast<int>(outcomes_.size()) - reached) + " of " +
                      std::to_string(outcomes_.size()) + " cutter poses not reached" +
                      (contacts_ > 0 ? ", " + std::to_string(contacts_) + " arm contacts" : "");
  }
}

void ArmReachEvaluator::WriteFiles(const std::string& dir) const {
  std::ostringstream csv;
  csv << "goal,x,y,z,stack_reached,position_error_m,orientation_error_deg,ik_solutions,free_goals,path_length_rad,"
         "cutter_path_length_m,motion_seconds,tracking_error_max_rad,min_clearance_m,witness_clearance_m,contacts,"
         "failure\n";
  for (const ArmGoalOutcome& o : outcomes_) {
    csv << o.goal << ',' << o.x << ',' << o.y << ',' << o.z << ',' << o.stack_reached << ',' << o.position_error_m
        << ',' << o.orientation_error_deg << ',' << o.ik_solutions << ',' << o.free_goals << ',' << o.path_length_rad
        << ',' << o.cutter_path_length_m << ',' << o.motion_seconds << ',' << o.tracking_error_max_rad << ','
        << o.min_clearance_m << ',' << o.witness_clearance_m << ',' << o.contacts << ",\"" << o.failure << "\"\n";
  }
  WriteFileAtomically(dir + "/arm_goals.csv", csv.str());
}

}  // namespace trimbot::scenarios
