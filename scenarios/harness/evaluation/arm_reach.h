#pragma once
// The arm_reach scenario's ground-truth side: the random cutter poses (each with a witness joint
// configuration that reaches it without collision, so every pose is known to be feasible), and the
// evaluator that watches the arm work through them: the true cutter pose at each goal's end, the
// arm's contacts in MuJoCo, its true clearance and how closely the joints track the commands.
// The garden is what the simulator collides with (its convex hulls), checked with the robot's own
// collision model (FCL) at the true joint positions.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "evaluation/contact_events.h"
#include "evaluation/trial_result.h"
#include "loop/closed_loop.h"
#include "loop/scenario.h"
#include "trimbot/robot/collision_model.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {

struct ArmReachPose {
  Eigen::Isometry3d cutter_base = Eigen::Isometry3d::Identity();  // goal: the cutter frame in base_link
  Eigen::VectorXd witness;                                        // joint positions that reach it without collision
  double witness_clearance = 0.0;                                 // m
  double surface_distance = 0.0;  // m: the cutter's tip from the bush's collision surface
};

// The truth the arm works in: the garden objects near the robot as the simulator collides with
// them, and the ground, in the map frame; `bush` indexes the bush's hull among them.
struct ArmCollisionTruth {
  robot::CollisionModel model;
  std::vector<int> bush;  // environment indices of the bush's hulls
  Eigen::Vector3d bush_centre = Eigen::Vector3d::Zero();
  std::string garden;  // its name
};

// Throws InputError naming the scenario when the bush is not a bush of the garden.
ArmCollisionTruth MakeArmCollisionTruth(const Scenario& scenario, const sim::Simulator& simulator,
                                        const Eigen::Isometry3d& T_map_base);

// `spec.poses` poses, drawn by rejection from uniformly random joint positions (the trial's seed);
// throws InputError naming the scenario when too few are found (the bush out of the arm's reach).
std::vector<ArmReachPose> GenerateArmReachPoses(const Scenario& scenario, const ArmCollisionTruth& truth,
                                                const robot::RobotDescription& robot,
                                                const Eigen::Isometry3d& T_map_base, std::uint64_t seed);

class ArmReachEvaluator : public Observer {
 public:
  // `on_reached(goal)` is called when the stack reports a goal reached (for renders).
  ArmReachEvaluator(const ArmReach& spec, std::vector<ArmReachPose> poses, ArmCollisionTruth* truth,
                    std::function<void(int)> on_reached = {});
  void Observe(const StepView& step) override;
  // Fills the result's arm goals and counts, and success (all reached, no contact).
  void Finish(TrialResult* result) const;
  // arm_goals.csv: one row per goal.
  void WriteFiles(const std::string& dir) const;

 private:
  ArmReach spec_;
  std::vector<ArmReachPose> poses_;
  ArmCollisionTruth* truth_;
  std::function<void(int)> on_reached_;
  std::vector<ArmGoalOutcome> outcomes_;
  ContactEvents contact_events_;
  int contacts_ = 0;
  int current_ = 0;  // the goal the stack works on
  long steps_ = 0;
  double min_clearance_ = 1e9;
  std::vector<double> planning_seconds_;
};

}  // namespace trimbot::scenarios
