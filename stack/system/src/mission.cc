#include "mission.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "scoped_timer.h"

namespace trimbot::stack {
namespace {

// How far from the side a bush goal asks for its approach may be (rad): the free side nearest to
// it within a quarter turn either way (a box's corners are 45 deg off its faces' normals).
constexpr double kSideTolerance = M_PI / 4.0;

// A planar point through a (planar) transform.
Eigen::Vector2d Apply(const Eigen::Isometry3d& T, const Eigen::Vector2d& p) {
  return (T * Eigen::Vector3d(p.x(), p.y(), 0.0)).head<2>();
}

MissionState ToMission(Navigator::Mode mode) {
  switch (mode) {
    case Navigator::Mode::kIdle:
      return MissionState::kIdle;
    case Navigator::Mode::kFollowing:
    case Navigator::Mode::kBackingOff:
      return MissionState::kDriving;
    case Navigator::Mode::kDone:
      return MissionState::kDone;
    case Navigator::Mode::kFailed:
      return MissionState::kFailed;
  }
  return MissionState::kIdle;
}

}  // namespace

const char* ToString(MissionState state) {
  switch (state) {
    case MissionState::kIdle:
      return "idle";
    case MissionState::kDriving:
      return "driving";
    case MissionState::kReaching:
      return "reaching";
    case MissionState::kDone:
      return "done";
    case MissionState::kFailed:
      return "failed";
  }
  return "?";
}

Goal Goal::ApproachBush(const Eigen::Vector2d& centre, const perception::BushShape& shape) {
  Goal goal(centre);
  goal.bush = shape;
  return goal;
}

Goal Goal::TrimBush(const Eigen::Vector2d& centre, const perception::BushShape& shape) {
  Goal goal = ScanBush(centre, shape);
  goal.cut = true;
  return goal;
}

Goal Goal::ScanBush(const Eigen::Vector2d& centre, const perception::BushShape& shape) {
  Goal goal = ApproachBush(centre, shape);
  goal.trim = true;
  return goal;
}

bool HasBushGoal(const std::vector<Goal>& goals) {
  return std::any_of(goals.begin(), goals.end(), [](const Goal& g) { return g.bush.has_value(); });
}

bool HasTrimGoal(const std::vector<Goal>& goals) {
  return std::any_of(goals.begin(), goals.end(), [](const Goal& g) { return g.trim; });
}

Mission::Mission(const StackParameters& parameters, const Eigen::Vector2d& arm_axis, const Ekf& ekf,
                 const GyroOdometry& servo_odometry, arm::ArmExecutive* arm, trimming::TrimExecutive* trim)
    : parameters_(parameters),
      arm_axis_(arm_axis),
      ekf_(ekf),
      servo_odometry_(servo_odometry),
      arm_(arm),
      trim_(trim),
      servo_(parameters.bush_approach.servo, arm_axis) {}

void Mission::SetGoals(const std::vector<Goal>& goals) {
  goals_ = goals;
  next_goal_ = 0;
  failed_ = false;
}

void Mission::SetArmGoals(const std::vector<Eigen::Isometry3d>& cutter_poses) {
  arm_->SetGoals(cutter_poses);
  arm_goals_ = !cutter_poses.empty();
}

Eigen::Vector2d Mission::ApproachPoint(const Goal& goal, const Eigen::Vector2d& from,
                                       const Navigator& navigator) const {
  // Of the sides of the bush where the base's outline at the standoff clears the map (other than
  // the bush), the nearest to where the robot comes from whose approach point the outline fits at
  // facing the bush (the servo turns there to face it); failing that, one where it fits at all.
  // A goal that names its side: the free side nearest to it, within kSideTolerance.
  // The arm's axis surface_gap from the outline on that side, the approach point approach_margin further.
  const auto standoff = [&](double side) {
    return goal.bush->StandoffRadius(side) + parameters_.bush_approach.servo.surface_gap;
  };
  const auto reach = [&](double side) {
    return standoff(side) + parameters_.bush_approach.approach_margin + arm_axis_.x();
  };
  // Sides every 10 deg; a box only towards its corners (+-15 deg), where two faces show: seen
  // face-on, a box's centre along the face rests on its two leafy edges alone (3 deg off measured).
  std::vector<double> sides;
  if (goal.bush->kind == perception::BushShape::Kind::kBox) {
    for (int k = 0; k < 4; ++k) {
      for (double offset : {0.0, -15.0, 15.0}) {
        sides.push_back(goal.bush->yaw + (45.0 + 90.0 * k + offset) * M_PI / 180.0);
      }
    }
  } else {
    for (int k = 0; k < 36; ++k) sides.push_back(2.0 * M_PI * k / 36.0);
  }
  if (goal.side) {
    sides.erase(std::remove_if(sides.begin(), sides.end(),
                               [&](double angle) { return std::abs(WrapAngle(angle - *goal.side)) > kSideTolerance; }),
                sides.end());
    if (sides.empty()) sides.push_back(*goal.side);  // a box's corner is that far off: the side itself
  }
  for (const bool facing_the_bush : {true, false}) {
    std::optional<Eigen::Vector2d> best;
    double best_score = 0.0;
    for (const double angle : sides) {
      const Eigen::Vector2d side(std::cos(angle), std::sin(angle));
      const Eigen::Vector2d approach = goal.position + reach(angle) * side;
      const Eigen::Vector2d at_standoff = goal.position + (standoff(angle) + arm_axis_.x()) * side;
      const Pose2 facing{at_standoff.x(), at_standoff.y(), angle + M_PI};
      const bool fits = facing_the_bush ? navigator.planner().Valid({approach.x(), approach.y(), angle + M_PI})
                                        : navigator.planner().FreeHeading(approach).has_value();
      const double wanted = 2.0 * parameters_.navigation.stop_clearance;
      if (!fits || navigator.OutlineClearance(facing, wanted) < wanted) continue;
      const double score = goal.side ? std::abs(WrapAngle(angle - *goal.side)) : (approach - from).norm();
      if (!best || score < best_score) {
        best = approach;
        best_score = score;
      }
    }
    if (best) return *best;
  }
  // No side is free: the side asked for, or straight from where the robot comes (the navigator
  // moves the point or says why).
  const Eigen::Vector2d away = goal.side ? Eigen::Vector2d(std::cos(*goal.side), std::sin(*goal.side))
                               : (from - goal.position).norm() > 1e-6 ? (from - goal.position).normalized()
                                                                      : Eigen::Vector2d(-1.0, 0.0);
  return goal.position + reach(std::atan2(away.y(), away.x())) * away;
}

void Mission::StartSegment(Navigator* navigator) {
  const Pose2 estimate = ekf_.Estimate().pose;
  Eigen::Vector2d from(estimate.x, estimate.y);
  std::vector<NavigationGoal> points;
  bush_goal_ = -1;
  servoing_ = false;
  for (int i = next_goal_; i < static_cast<int>(goals_.size()); ++i) {
    const Goal& goal = goals_[static_cast<std::size_t>(i)];
    if (goal.bush) {
      points.push_back(ApproachPoint(goal, from, *navigator));
      const Eigen::Vector2d side = points.back().position - goal.position;
      approach_side_ = std::atan2(side.y(), side.x());
      bush_goal_ = i;
      break;
    }
    points.push_back({goal.position, goal.yaw});
    from = goal.position;
  }
  navigator->SetGoals(points, next_goal_);
  if (bush_goal_ >= 0) {
    ExpectBush();
    bush_status_ = BushApproachStatus{};
    bush_status_.goal = bush_goal_;
    bush_status_.target_distance = servo_.target_distance();
    bush_status_.target_bearing = parameters_.bush_approach.servo.bearing;
  }
}

void Mission::ExpectBush() {
  const Goal& goal = goals_[static_cast<std::size_t>(bush_goal_)];
  servo_.Expect(Apply(MapFromServoFrame().inverse(), goal.position), goal.bush->StandoffRadius(approach_side_));
}

void Mission::CountSighting(bool tracked) {
  ++bush_status_.frames;
  bush_status_.tracked += tracked ? 1 : 0;
}

Eigen::Isometry3d Mission::MapFromServoFrame() const {
  // The EKF's map pose of base_link and the gyro odometry's pose of it, at the same time.
  return ToIsometry(ekf_.Estimate().pose) * ToIsometry(servo_odometry_.pose()).inverse();
}

void Mission::HandleNavigationEvents(double stamp, Telemetry* telemetry) {
  for (NavigationEvent& event : telemetry->events) {
    if (event.type != NavigationEvent::Type::kGoalReached || event.goal != bush_goal_) continue;
    // By map at the bush's approach point: the bush goal itself is reached by visual servoing.
    event.type = NavigationEvent::Type::kApproachReached;
    servoing_ = true;
    servo_.Start(stamp);
  }
}

void Mission::RunBushServo(double stamp, Navigator* navigator, messages::RobotCommands* commands,
                           Telemetry* telemetry) {
  commands->base = servo_.Update(stamp, servo_odometry_.pose());
  if (servo_.mode() == BushServo::Mode::kDone) {
    const Eigen::Vector2d db = servo_.DistanceBearing(servo_odometry_.pose());
    FinishBushGoal(stamp, true, std::to_string(db.x()) + " m, " + std::to_string(db.y() * 180.0 / M_PI) + " deg",
                   navigator, telemetry);
  } else if (servo_.mode() == BushServo::Mode::kFailed) {
    FinishBushGoal(stamp, false, servo_.failure(), navigator, telemetry);
  }
}

void Mission::FinishBushGoal(double stamp, bool reached, const std::string& detail, Navigator* navigator,
                             Telemetry* telemetry) {
  NavigationEvent event;
  event.stamp = stamp;
  event.type = reached ? NavigationEvent::Type::kGoalReached : NavigationEvent::Type::kGoalFailed;
  event.goal = bush_goal_;
  event.detail = detail;
  event.position = Apply(MapFromServoFrame(), servo_.centre());  // the bush's centre as tracked
  telemetry->events.push_back(event);
  servoing_ = false;
  if (!reached && parameters_.navigation.stop_on_failure) {
    failed_ = true;
    return;
  }
  if (reached && goals_[static_cast<std::size_t>(bush_goal_)].trim) {
    StartTrim(stamp);
    return;
  }
  // The rest of the mission (none: the navigator is done); a bush not reached is given up as the
  // navigator gives up a point goal.
  next_goal_ = bush_goal_ + 1;
  StartSegment(navigator);
}

void Mission::StartTrim(double stamp) {
  const Goal& goal = goals_[static_cast<std::size_t>(bush_goal_)];
  const perception::BushShape& bush = *goal.bush;
  perception::TopiaryShape expected;
  // The plan's shape: exponents as the garden's topiary shapes have them (topiary_fit.h).
  expected.horizontal_exponent = bush.kind == perception::BushShape::Kind::kBox ? 6.0 : 2.0;
  expected.vertical_exponent = bush.kind == perception::BushShape::Kind::kEllipsoid ? 2.0 : 6.0;
  const Eigen::Vector2d centre = Apply(ToIsometry(servo_odometry_.pose()).inverse(), servo_.centre());
  expected.half = bush.size / 2.0;
  expected.centre = Eigen::Vector3d(centre.x(), centre.y(), bush.base_height + expected.half.z());
  expected.yaw = WrapAngle(bush.yaw - ekf_.Estimate().pose.yaw);
  // Extents that differ by less than a tape survey's error (2 cm a point, two points an extent:
  // kSurveyTolerance) are one: the plan's ball or round shape.
  constexpr double kSurveyTolerance = 0.05;  // m
  const bool round = std::abs(bush.size.x() - bush.size.y()) < kSurveyTolerance;
  const perception::AxesTied tied = round && std::abs(bush.size.x() - bush.size.z()) < kSurveyTolerance
                                        ? perception::AxesTied::kAll
                                    : round ? perception::AxesTied::kHorizontal
                                            : perception::AxesTied::kNone;
  // The bush by the first goal that names it (its surveyed centre): trims of it share their scans.
  int bush_id = bush_goal_;
  for (int i = 0; i < bush_goal_; ++i) {
    const Goal& other = goals_[static_cast<std::size_t>(i)];
    if (other.bush && other.position == goal.position) {
      bush_id = i;
      break;
    }
  }
  trim_->Start(stamp, expected, tied, bush_id, ToIsometry(ekf_.Estimate().pose), goal.cut);
  trimming_ = true;
  advance_from_ = servo_odometry_.pose();
  advance_stopped_ = -1.0;
}

bool Mission::AdvanceToTrim(messages::RobotCommands* commands) {
  const BushServoParameters& servo = parameters_.bush_approach.servo;
  const double advance = servo.surface_gap - parameters_.trim.surface_gap;
  const Pose2 now = servo_odometry_.pose();
  const double remaining = advance - std::hypot(now.x - advance_from_.x, now.y - advance_from_.y);
  messages::BaseVelocityCommand command;
  if (remaining > servo.distance_tolerance) {
    command.linear = std::clamp(servo.gain * remaining, servo.min_speed, servo.max_speed);
    commands->base = command;
    return false;
  }
  commands->base = command;
  return true;
}

void Mission::RunTrim(double stamp, Navigator* navigator, messages::RobotCommands* commands, Telemetry* telemetry) {
  ScopedTimer timer(&telemetry->timings.arm);
  commands->base = messages::BaseVelocityCommand{};
  if (trim_->mode() == trimming::TrimExecutive::Mode::kFitted) {
    // Scanned from the approach's standoff (the whole bush in view), cut from closer. Once there,
    // the base settles (as at the servo's arrival).
    if (!AdvanceToTrim(commands)) {
      advance_stopped_ = -1.0;
    } else if (advance_stopped_ < 0.0) {
      advance_stopped_ = stamp;
    } else if (stamp - advance_stopped_ >= parameters_.bush_approach.servo.settle_time) {
      trim_->StandsAt(ToIsometry(servo_odometry_.pose()).inverse() * ToIsometry(advance_from_));
    }
  }
  if (auto command = trim_->Update(stamp)) commands->arm = *command;
  commands->cutter = messages::CutterCommand{trim_->cutting()};
  telemetry->trim = TrimStatus{bush_goal_, trimming::ToString(trim_->mode()), trim_->Stage(stamp)};
  if (trim_->active()) return;
  telemetry->trim_results.push_back({bush_goal_, trim_->report()});
  telemetry->trim.reset();
  trimming_ = false;
  next_goal_ = bush_goal_ + 1;
  StartSegment(navigator);
}

void Mission::UpdateTelemetry(const Navigator& navigator, Telemetry* telemetry) {
  state_ = failed_     ? MissionState::kFailed
           : trimming_ ? MissionState::kReaching
           : servoing_ ? MissionState::kDriving
                       : ToMission(navigator.mode());
  telemetry->mission = state_;
  telemetry->current_goal = servoing_ || trimming_ || failed_ ? bush_goal_ : navigator.current_goal();
  if (bush_goal_ < 0) {
    telemetry->bush.reset();
    return;
  }
  bush_status_.mode = servoing_ ? ToString(servo_.mode()) : "navigating";
  const Eigen::Vector2d db = servo_.DistanceBearing(servo_odometry_.pose());
  bush_status_.distance = db.x();
  bush_status_.bearing = db.y();
  telemetry->bush = bush_status_;
}

bool Mission::NavigationGoalsDone() const {
  return goals_.empty() || state_ == MissionState::kDone || state_ == MissionState::kReaching;
}

void Mission::RunArm(double stamp, messages::RobotCommands* commands, Telemetry* telemetry) {
  ScopedTimer timer(&telemetry->timings.arm);
  if (state_ == MissionState::kFailed || !NavigationGoalsDone()) return;
  if (auto command = arm_->Update(stamp)) commands->arm = *command;
  telemetry->arm_results = arm_->TakeResults();
  ArmStatus status;
  status.mode = arm::ToString(arm_->mode());
  status.goal = arm_->current_goal();
  status.perceived_cells = arm_->perceived_cells();
  status.target.assign(arm_->target().data(), arm_->target().data() + arm_->target().size());
  telemetry->arm = status;
  state_ = arm_->mode() == arm::ArmExecutive::Mode::kDone ? MissionState::kDone : MissionState::kReaching;
  telemetry->mission = state_;
}

}  // namespace trimbot::stack
