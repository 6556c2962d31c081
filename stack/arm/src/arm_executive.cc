#include "trimbot/arm/arm_executive.h"

#include <array>
#include <cmath>
#include <map>
#include <sstream>

namespace trimbot::arm {
namespace {

Eigen::VectorXd ToVector(const messages::ArmJointState& joints) {
  return Eigen::Map<const Eigen::VectorXd>(joints.position.data(), static_cast<int>(joints.position.size()));
}

}  // namespace

int BuildPerceivedEnvironment(const robot::RobotDescription& description, const ArmExecutiveParameters& parameters,
                              const std::vector<Eigen::Vector3d>& points,
                              const std::vector<Eigen::Matrix3d>& covariances,
                              robot::CollisionEnvironment* environment) {
  // The arm's base: the parent link of its first joint.
  const std::string arm_base_link = description.urdf().getJoint(robot::RobotFrames::ArmJoint(0))->parent_link_name;
  const Eigen::Vector3d arm_base = description.FramePose(arm_base_link).translation();
  const auto [low, high] = description.BaseOutline();
  const Eigen::Vector2d body_min = low.array() - parameters.body_margin,
                        body_max = high.array() + parameters.body_margin;
  // Points per cell, of those that can matter to the arm and are neither ground nor the robot.
  const double cell = parameters.cell;
  std::map<std::array<int, 3>, int> counts;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    if (!p.allFinite() || p.z() < 2.0 * parameters.ground_clearance) continue;
    if ((p - arm_base).norm() > parameters.reach) continue;
    if ((p.head<2>().array() >= body_min.array()).all() && (p.head<2>().array() <= body_max.array()).all()) continue;
    if (i < covariances.size() &&
        covariances[i].diagonal().maxCoeff() > parameters.max_point_sigma * parameters.max_point_sigma) {
      continue;
    }
    ++counts[{static_cast<int>(std::floor(p.x() / cell)), static_cast<int>(std::floor(p.y() / cell)),
              static_cast<int>(std::floor(p.z() / cell))}];
  }
  // Grown by the margin: every cell within it of an occupied one.
  const int grow = static_cast<int>(std::ceil(parameters.margin / cell - 1e-9));
  std::map<std::array<int, 3>, bool> occupied;
  for (const auto& [key, count] : counts) {
    if (count < parameters.min_points_per_cell) continue;
    for (int dx = -grow; dx <= grow; ++dx) {
      for (int dy = -grow; dy <= grow; ++dy) {
        for (int dz = -grow; dz <= grow; ++dz) occupied[{key[0] + dx, key[1] + dy, key[2] + dz}] = true;
      }
    }
  }
  std::vector<Eigen::Vector3d> centres;
  centres.reserve(occupied.size());
  for (const auto& [key, unused] : occupied) {
    centres.emplace_back((key[0] + 0.5) * cell, (key[1] + 0.5) * cell, (key[2] + 0.5) * cell);
  }
  environment->Clear();
  environment->AddGround("ground", parameters.ground_clearance);
  environment->AddOccupiedPoints("perceived", centres, cell);
  return static_cast<int>(centres.size());
}

const char* ToString(ArmExecutive::Mode mode) {
  switch (mode) {
    case ArmExecutive::Mode::kIdle:
      return "idle";
    case ArmExecutive::Mode::kWaitingForEnvironment:
      return "waiting_for_environment";
    case ArmExecutive::Mode::kMoving:
      return "moving";
    case ArmExecutive::Mode::kSettling:
      return "settling";
    case ArmExecutive::Mode::kDone:
      return "done";
  }
  return "?";
}

ArmExecutive::ArmExecutive(const robot::RobotDescription& description, const ArmExecutiveParameters& parameters)
    : parameters_(parameters),
      kinematics_(description),
      collision_(std::make_unique<robot::CollisionModel>(description, description.ArmJointNames(),
                                                         parameters.planner.body_clearance)),
      planner_(std::make_unique<ArmPlanner>(kinematics_, *collision_, parameters.planner)),
      description_(description) {
  collision_->environment().AddGround("ground", parameters_.ground_clearance);
}

ArmExecutive::~ArmExecutive() = default;

void ArmExecutive::SetGoals(const std::vector<Eigen::Isometry3d>& cutter_poses) {
  goals_ = cutter_poses;
  goal_ = 0;
  if (!goals_.empty()) kinematics_.PrepareDatabase(parameters_.planner.ik);  // not inside the first plan
  mode_ = goals_.empty() ? Mode::kDone : Mode::kWaitingForEnvironment;
}

void ArmExecutive::SetJointState(const messages::ArmJointState& joints) {
  joints_ = joints;
  if (mode_ != Mode::kMoving) return;
  // How far the joints lag the trajectory at the encoders' stamp.
  Eigen::VectorXd planned, velocity;
  plan_.trajectory.Sample(joints.stamp - motion_start_, &planned, &velocity);
  result_.tracking_error_max = std::max(result_.tracking_error_max, (ToVector(joints) - planned).cwiseAbs().maxCoeff());
}

void ArmExecutive::SetPerceivedPoints(const std::vector<Eigen::Vector3d>& points,
                                      const std::vector<Eigen::Matrix3d>& covariances) {
  perceived_cells_ =
      BuildPerceivedEnvironment(description_, parameters_, points, covariances, &collision_->environment());
  environment_ready_ = true;
  planner_->ResetRoadmap();
}

std::optional<messages::ArmCommand> ArmExecutive::Update(double stamp) {
  if (mode_ == Mode::kWaitingForEnvironment) {
    if (!environment_ready_ || !joints_) return std::nullopt;
    StartGoal(stamp);
  }
  if (mode_ != Mode::kMoving && mode_ != Mode::kSettling) return std::nullopt;
  const Eigen::VectorXd measured = ToVector(*joints_);
  if (mode_ == Mode::kMoving) {
    Eigen::VectorXd velocity;
    plan_.trajectory.Sample(stamp - motion_start_, &target_, &velocity);
    if (stamp - motion_start_ >= plan_.trajectory.duration()) {
      mode_ = Mode::kSettling;
      settle_start_ = stamp;
    }
  } else {
    const double off = (measured - target_).cwiseAbs().maxCoeff();
    if (off <= parameters_.settle_tolerance) {
      FinishGoal(stamp, true, "");
    } else if (stamp - settle_start_ > parameters_.settle_timeout) {
      std::ostringstream why;
      why << "did not settle within " << parameters_.settle_timeout << " s: a joint is " << off << " rad off";
      FinishGoal(stamp, false, why.str());
    }
    if (mode_ == Mode::kSettling && goal_ != result_.goal) StartGoal(stamp);  // finished: the next goal
    if (mode_ != Mode::kMoving && mode_ != Mode::kSettling) return std::nullopt;
  }
  messages::ArmCommand command;
  command.mode = messages::ArmCommand::Mode::kPosition;
  for (int i = 0; i < target_.size(); ++i) command.position[static_cast<size_t>(i)] = target_(i);
  return command;
}

void ArmExecutive::StartGoal(double stamp) {
  // Goals that cannot be planned are finished at once, with the reason; the next is tried.
  while (goal_ < static_cast<int>(goals_.size())) {
    result_ = ArmGoalResult();
    result_.goal = goal_;
    result_.start = stamp;
    plan_ = planner_->PlanToPose(ToVector(*joints_), goals_[static_cast<size_t>(goal_)]);
    result_.ik_solutions = plan_.ik_solutions;
    result_.free_goals = plan_.free_goals;
    result_.validity_checks = plan_.validity_checks;
    result_.planning_seconds = plan_.planning_seconds;
    if (plan_.ok) {
      result_.path_length = plan_.path_length;
      result_.cutter_path_length = plan_.cutter_path_length;
      result_.motion_duration = plan_.trajectory.duration();
      motion_start_ = stamp;
      target_ = plan_.trajectory.positions.front();
      mode_ = Mode::kMoving;
      return;
    }
    FinishGoal(stamp, false, plan_.failure);
  }
}

void ArmExecutive::FinishGoal(double stamp, bool reached, const std::string& failure) {
  result_.end = stamp;
  result_.reached = reached;
  result_.failure = failure;
  const Eigen::Isometry3d at = kinematics_.EndEffectorPose(ToVector(*joints_));
  const Eigen::Isometry3d& goal = goals_[static_cast<size_t>(goal_)];
  result_.position_error = (at.translation() - goal.translation()).norm();
  result_.orientation_error = Eigen::AngleAxisd(at.linear().transpose() * goal.linear()).angle();
  finished_.push_back(result_);
  ++goal_;
  if (goal_ >= static_cast<int>(goals_.size())) {
    mode_ = Mode::kDone;
    target_.resize(0);
  }
}

std::vector<ArmGoalResult> ArmExecutive::TakeResults() {
  std::vector<ArmGoalResult> out;
  out.swap(finished_);
  return out;
}

}  // namespace trimbot::arm
