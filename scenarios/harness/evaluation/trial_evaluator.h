#pragma once
// Evaluation of a navigation trial against the ground truth, as an observer of the closed loop:
// estimate errors (EKF, wheel odometry, pose fixes at their own stamps), path length, collisions
// (contacts with garden objects), goals reached (judged on the ground truth when the stack says it
// arrived), replans and recoveries from the stack's events. Writes ground_truth.tum, ekf.tum,
// wheel_odometry.tum, pose_fixes.tum (TUM, usable with evo) and events.csv. Bush goals: the arm's
// true distance and bearing to the bush's true centre at arrival against the stack's target and
// its own estimate, and every frame the stack looked for the bush (bush_frames.csv). With the
// stack's visual localization, every frame it tried and what came of it (localization.csv).
#include <Eigen/Core>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "evaluation/localization_log.h"
#include "evaluation/trial_result.h"
#include "loop/closed_loop.h"
#include "loop/prepared_trial.h"
#include "trimbot/garden/garden_tools.h"

namespace trimbot::scenarios {

// The goals as a trial's result lists them before any is reached (also a crashed trial's).
std::vector<GoalResult> UnreachedGoals(const std::vector<GoalTruth>& goals);

// When a goal counts as reached (ground truth at the robot's declared arrival).
struct GoalCriteria {
  double tolerance = 0.3;                    // m from a point goal
  double yaw_tolerance = 0.25;               // rad from a point goal's heading, if it has one
  double bush_distance = 0.03;               // m from the standoff the stack aimed at (arm's axis to the centre)
  double bush_bearing = 3.0 * M_PI / 180.0;  // rad from the bearing it aimed at
  Eigen::Vector2d arm_axis = Eigen::Vector2d::Zero();  // base_link: where bush distances are measured from
};

class TrialEvaluator : public Observer {
 public:
  // `fix_history_seconds`: how late a pose fix may arrive and still be judged at its stamp.
  TrialEvaluator(const std::vector<GoalTruth>& goals, const GoalCriteria& criteria, double fix_history_seconds);

  void Observe(const StepView& step) override;
  // Also measure the smallest clearance between the robot's base outline (a rectangle in
  // base_link, RobotDescription::BaseOutline) at its true pose and the footprints of the garden as
  // it is (`world`: its objects' parts below `clearance_height`), exact to 1 mm; negative: how deep
  // a footprint reaches into the outline.
  void MeasureClearance(const garden::Garden& world, double clearance_height, const Eigen::Vector2d& outline_min,
                        const Eigen::Vector2d& outline_max);

  // Completes `result` (status, goals, counts, errors) from what was observed; `finished`: the
  // stack ended its mission before the time limit.
  void Finish(bool finished, double time_limit, const stack::Telemetry& final_telemetry, TrialResult* result);
  // Writes the trajectories and events into `dir`.
  void WriteFiles(const std::string& dir) const;

 private:
  struct PlanarPose {
    double t = 0.0, x = 0.0, y = 0.0, yaw = 0.0;
  };
  static PlanarPose Planar(double t, const Eigen::Isometry3d& pose);
  void MeasureClearanceAt(const PlanarPose& truth);
  const PlanarPose* TruthAt(double stamp) const;
  void ObserveEvents(const StepView& step, const PlanarPose& truth);
  void ObserveContacts(const StepView& step);
  void ObserveBushSightings(const StepView& step);
  // The arm's true distance (m) and bearing (rad) to goal `goal`'s bush, from the pose `truth`.
  Eigen::Vector2d TrueBushDistanceBearing(const PlanarPose& truth, int goal) const;
  void JudgeBushGoal(const stack::NavigationEvent& event, const PlanarPose& truth, GoalResult* goal) const;
  void Sample(const StepView& step, const PlanarPose& truth);
  double LocalizationRate() const;

  std::vector<GoalTruth> truths_;
  GoalCriteria criteria_;
  double fix_history_seconds_;
  std::vector<GoalResult> goals_;
  std::vector<std::optional<stack::BushApproachStatus>> bush_status_;  // per goal: the latest seen
  std::vector<BushFrame> bush_frames_;
  EstimateErrors ekf_{"ekf", {}, {}, {}}, odometry_{"wheel_odometry", {}, {}, {}}, fixes_{"pose_fixes", {}, {}, {}};
  std::string truth_tum_, ekf_tum_, odometry_tum_, fixes_tum_;
  LocalizationLog localization_log_;  // the stack's own visual localization, frame by frame
  std::string events_csv_ = "t,event,goal,detail\n";
  std::deque<PlanarPose> truth_history_;  // the last seconds, to judge late fixes at their stamps
  bool have_previous_ = false;
  PlanarPose previous_;
  double path_length_ = 0.0;
  bool in_contact_ = false;
  int collisions_ = 0;
  double contact_seconds_ = 0.0;
  int plans_ = 0, recoveries_ = 0;
  std::vector<bool> goal_planned_;
  int goals_given_up_ = 0;  // kGoalFailed events (with stop_on_failure false the mission goes on)
  std::vector<double> sample_times_, fix_stamps_;  // for the localization rate
  long steps_ = 0;
  double timestep_ = 0.0;
  // Clearance: the world's footprints as points along their boundaries (empty: not measured), and
  // the base's outline in base_link.
  struct Footprint {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    double reach = 0.0;  // m from the centre to the farthest boundary point
    std::vector<Eigen::Vector2d> boundary;
  };
  std::vector<Footprint> footprints_;
  Eigen::Vector2d outline_min_ = Eigen::Vector2d::Zero(), outline_max_ = Eigen::Vector2d::Zero();
  double min_clearance_ = std::numeric_limits<double>::infinity();
};

}  // namespace trimbot::scenarios
