#pragma once
// The trim goals' ground-truth side. The simulator cuts each trim bush's foliage as the blade
// sweeps it (sim::Simulator::foliage); this observer measures it against the bush's target shape
// before the trial and after, times the cut, counts what the arm touched while trimming - MuJoCo's
// contacts of the arm (the bush's wood, the ground, the robot itself) and any arm link other than
// the blade reaching into the foliage (its collision cylinders against the foliage as cut so far) -
// and sets the stack's fitted target (base_link, placed by the true base pose) against the true one.
#include <Eigen/Geometry>
#include <chrono>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "evaluation/contact_events.h"
#include "evaluation/trial_result.h"
#include "loop/closed_loop.h"
#include "loop/scenario.h"
#include "trimbot/garden/foliage.h"
#include "trimbot/robot/robot_description.h"
#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {

// The trim goals' bushes (object ids, each once): what the simulator makes cuttable.
std::vector<int> TrimBushes(const Scenario& scenario);

class TrimEvaluator : public Observer {
 public:
  // The simulator must have been made with TrimBushes(scenario) cuttable; it outlives the evaluator.
  TrimEvaluator(const sim::Simulator& simulator, const Scenario& scenario);
  void Observe(const StepView& step) override;
  // The trims' outcomes (result->trims, trim_timings); a trim that failed fails the trial.
  void Finish(TrialResult* result) const;
  // Per trim bush: foliage_<id>_before.ply and _after.ply (the leaf surface with its signed
  // distance to the target).
  void WriteFiles(const std::string& dir) const;
  // A trim bush's foliage as it was before the trial (the simulator has it as it is now).
  const garden::Foliage& before(int bush) const;

 private:
  struct Trim {
    int goal = 0;
    garden::Foliage before;
    TrimOutcome outcome;
    double started = -1.0;                                         // s: the stack's trim began (-1: not yet)
    std::chrono::steady_clock::time_point wall_started;            // the same, wall clock
    double wall_seconds = -1.0;                                    // wall clock from start to the stack's result
    Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();  // true, when it began
    double planning_seconds = -1.0;
    bool touching = false;
  };
  // An arm link other than the blade that reaches into the foliage at the true joint positions (the
  // first found; empty: none).
  std::string LinkInFoliage(const sim::GroundTruth& truth, const garden::Foliage& foliage) const;
  void Record(const stack::TrimResult& result, double now);

  const sim::Simulator& simulator_;
  std::vector<robot::LinkCylinder> links_;  // the arm's links but the blade
  std::vector<Trim> trims_;
  ContactEvents contact_events_;  // MuJoCo's arm contacts
  long steps_ = 0;
};

}  // namespace trimbot::scenarios
