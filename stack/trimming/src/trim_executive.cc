#include "trimbot/trimming/trim_executive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "trimbot/common/points_kd_tree.h"
#include "trimbot/common/wall_clock.h"

namespace trimbot::trimming {
namespace {

Eigen::VectorXd ToVector(const messages::ArmJointState& joints) {
  return Eigen::Map<const Eigen::VectorXd>(joints.position.data(), static_cast<int>(joints.position.size()));
}

// The joint path shifted to begin at `first` (the same arm poses: `first` differs from its first
// configuration by whole turns of continuous joints).
std::vector<Eigen::VectorXd> BeginningAt(std::vector<Eigen::VectorXd> path, const Eigen::VectorXd& first) {
  const Eigen::VectorXd shift = first - path.front();
  for (Eigen::VectorXd& q : path) q += shift;
  return path;
}

// The q-quantile of `values` (0 when empty).
double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

}  // namespace

const char* ToString(TrimExecutive::Mode mode) {
  switch (mode) {
    case TrimExecutive::Mode::kIdle:
      return "idle";
    case TrimExecutive::Mode::kWaitingForPoints:
      return "scanning";
    case TrimExecutive::Mode::kFitted:
      return "fitted";
    case TrimExecutive::Mode::kPlanning:
      return "planning";
    case TrimExecutive::Mode::kCutting:
      return "cutting";
    case TrimExecutive::Mode::kSettling:
      return "settling";
    case TrimExecutive::Mode::kDone:
      return "done";
  }
  return "?";
}

CuttingPathOptions TrimParameters::PathOptions() const {
  CuttingPathOptions options = path;
  options.velocity_scale = planner.velocity_scale;
  options.acceleration = planner.acceleration;
  options.ik = planner.ik;
  return options;
}

TrimExecutive::TrimExecutive(const robot::RobotDescription& description, const TrimParameters& parameters)
    : parameters_(parameters),
      kinematics_(description),
      T_cutter_blade_(description.BladeInCutter()),
      blade_radius_(description.BladeRadius()),
      housing_radius_(description.ArmLinkCylinders().back().radius),  // link 6 carries the cutter
      blade_thickness_(description.BladeThickness()),
      collision_(std::make_unique<robot::CollisionModel>(description, description.ArmJointNames(),
                                                         parameters.planner.body_clearance)),
      planner_(std::make_unique<arm::ArmPlanner>(kinematics_, *collision_, parameters.planner)) {
  parameters_.path = parameters.PathOptions();
  const std::vector<robot::LinkCylinder> cylinders = description.ArmLinkCylinders();
  const std::vector<std::string>& links = kinematics_.links();
  for (std::size_t c = 0; c + 1 < cylinders.size(); ++c) {  // the last, link 6, carries the cutter
    const auto at = std::find(links.begin(), links.end(), cylinders[c].link);
    if (at != links.end()) arm_links_.emplace_back(static_cast<std::size_t>(at - links.begin()), cylinders[c]);
  }
}

TrimExecutive::~TrimExecutive() = default;

void TrimExecutive::SetDatabase(const std::string& path) {
  database_ = CuttingPathDatabase::Load(path, ArmSignature(kinematics_, T_cutter_blade_));
}

void TrimExecutive::Start(double stamp, const perception::TopiaryShape& expected, perception::AxesTied tied, int bush,
                          const Eigen::Isometry3d& T_map_base, bool cut) {
  cut_ = cut;
  expected_ = expected;
  tied_ = tied;
  bush_ = bush;
  T_map_base_ = T_map_base;
  points_.clear();
  covariances_.clear();
  report_ = TrimReport();
  report_.start = stamp;
  kinematics_.PrepareDatabase(parameters_.path.ik);  // not inside the plan
  mode_ = Mode::kWaitingForPoints;
}

void TrimExecutive::SetPerceivedPoints(const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<Eigen::Matrix3d>& covariances) {
  points_ = points;
  covariances_ = covariances;
}

void TrimExecutive::SetJointState(const messages::ArmJointState& joints) { joints_ = joints; }

void TrimExecutive::StandsAt(const Eigen::Isometry3d& T_now_scan) {
  if (mode_ != Mode::kFitted) return;
  target_shape_.centre = T_now_scan * target_shape_.centre;
  for (Eigen::Vector3d& p : leaves_) p = T_now_scan * p;
  const Eigen::Vector3d x = T_now_scan.linear().col(0);
  target_shape_.yaw += std::atan2(x.y(), x.x());
  mode_ = Mode::kPlanning;
}

std::vector<Eigen::Vector3d> TrimExecutive::BushPoints() const {
  const double max_variance = parameters_.max_point_sigma * parameters_.max_point_sigma;
  std::vector<Eigen::Vector3d> bush;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const Eigen::Vector3d& p = points_[i];
    if (!p.allFinite() || p.z() < parameters_.min_height) continue;
    if (i < covariances_.size() && covariances_[i].diagonal().maxCoeff() > max_variance) continue;
    if (expected_.RadialDistance(p) > parameters_.scan_margin) continue;
    bush.push_back(p);
  }
  return bush;
}

std::vector<Eigen::Vector3d> TrimExecutive::ScansOfTheBush() {
  const std::vector<Eigen::Vector3d> seen = BushPoints();
  std::vector<Eigen::Vector3d>& scans = scans_[bush_];  // map frame
  const Eigen::Isometry3d T_base_map = T_map_base_.inverse();
  const PointsAdaptor adaptor{seen};
  PointsKdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  tree.buildIndex();
  const double overlap = parameters_.scan_overlap * parameters_.scan_overlap;
  std::vector<Eigen::Vector3d> points = seen;
  for (const Eigen::Vector3d& earlier : scans) {
    const Eigen::Vector3d p = T_base_map * earlier;
    std::uint32_t index = 0;
    double d2 = 0.0;
    // Nothing of this scan near (or no point at all): a part only the earlier scans saw.
    if (tree.knnSearch(p.data(), 1, &index, &d2) == 0 || d2 > overlap) points.push_back(p);
  }
  for (const Eigen::Vector3d& p : seen) scans.push_back(T_map_base_ * p);  // joins them for later scans
  // Thinned evenly to max_points (the fit's time is linear in them).
  const double stride = std::max(1.0, static_cast<double>(points.size()) / parameters_.max_points);
  std::vector<Eigen::Vector3d> thinned;
  for (double k = 0.0; k < static_cast<double>(points.size()); k += stride) {
    thinned.push_back(points[static_cast<std::size_t>(k)]);
  }
  return thinned;
}

std::optional<messages::ArmCommand> TrimExecutive::Update(double stamp) {
  if (mode_ == Mode::kWaitingForPoints && !points_.empty()) Fit(stamp);
  if (mode_ == Mode::kPlanning && joints_) Plan(stamp);
  if (mode_ != Mode::kCutting && mode_ != Mode::kSettling) return std::nullopt;
  if (mode_ == Mode::kCutting) {
    Eigen::VectorXd velocity;
    trajectory_.Sample(stamp - motion_start_, &target_, &velocity);
    if (stamp - motion_start_ >= trajectory_.duration()) {
      mode_ = Mode::kSettling;
      settle_start_ = stamp;
    }
  } else {
    const double off = (ToVector(*joints_) - target_).cwiseAbs().maxCoeff();
    if (off <= parameters_.settle_tolerance) {
      report_.cut = true;
      Finish(stamp, "");
      return std::nullopt;
    }
    if (stamp - settle_start_ > parameters_.settle_timeout) {
      std::ostringstream why;
      why << "the arm did not settle at its start within " << parameters_.settle_timeout << " s: a joint is " << off
          << " rad off";
      Finish(stamp, why.str());
      return std::nullopt;
    }
  }
  messages::ArmCommand command;
  command.mode = messages::ArmCommand::Mode::kPosition;
  for (int i = 0; i < target_.size(); ++i) command.position[static_cast<std::size_t>(i)] = target_(i);
  return command;
}

std::string TrimExecutive::Stage(double stamp) const {
  if (mode_ != Mode::kCutting) return ToString(mode_);
  const double t = stamp - motion_start_;
  return t < cut_begins_ ? "moving in" : t > cut_ends_ ? "moving out" : "cutting";
}

void TrimExecutive::Fit(double stamp) {
  const auto begin = std::chrono::steady_clock::now();
  const std::vector<Eigen::Vector3d> bush = ScansOfTheBush();
  report_.points = static_cast<int>(bush.size());
  std::string failure;
  // The target stands on the plan's base, where the foliage starts (its foot hidden in the grass).
  perception::TopiaryFitOptions options = parameters_.fit;
  options.base_height = expected_.centre.z() - expected_.half.z();
  const std::optional<perception::TopiaryFit> fit = FitTopiary(bush, expected_, tied_, options, &failure);
  if (!fit) {
    Finish(stamp, "no target shape from the scan: " + failure);
    return;
  }
  report_.fit = fit->shape;
  target_shape_ = fit->shape;
  leaves_ = bush;
  std::vector<double> outside;
  for (const Eigen::Vector3d& p : bush) outside.push_back(std::max(0.0, fit->shape.RadialDistance(p)));
  report_.leaf_depth = Quantile(outside, parameters_.leaf_quantile);
  report_.fit_loss = fit->loss;
  report_.planning_seconds = SecondsSince(begin);
  mode_ = Mode::kFitted;
  if (!cut_) Finish(stamp, "");  // a scan only
}

void TrimExecutive::Plan(double stamp) {
  const auto begin = std::chrono::steady_clock::now();
  const perception::TopiaryShape& target = target_shape_;
  std::string failure;
  check_depth_ = CheckDepth(target, parameters_.blade_depth, parameters_.poses.spacing, blade_thickness_);
  const CuttingChecks checks =
      MakeCuttingChecks(kinematics_, T_cutter_blade_, collision_.get(), target, check_depth_, parameters_.planner,
                        [this](const Eigen::VectorXd& q) { return !ArmInLeaves(q); });
  planner_->ResetRoadmap();
  // Where the blade goes: blade_depth inside the fitted surface where the scan saw leaves over it.
  const BladeSurface blade_surface(target, parameters_.blade_depth,
                                   [this](const Eigen::Vector3d& d) { return LeavesSeenOver(d); });
  const Eigen::VectorXd start = ToVector(*joints_);
  CuttingPath path;
  double distance = 0.0;
  const StoredCuttingPath* stored = database_ ? database_->Nearest(target, &distance) : nullptr;
  std::ostringstream source;
  if (!database_) {
    source << "solved in full: no stored paths given";
  } else if (stored == nullptr) {
    source << "solved in full: no stored path of this shape";
  } else if (distance > parameters_.database_max_distance) {
    source << "solved in full: the nearest stored target is " << distance << " m off (more than "
           << parameters_.database_max_distance << " m)";
  } else {
    path = AdaptCuttingPath(kinematics_, T_cutter_blade_, start, *stored, blade_surface, checks.valid, checks.free_move,
                            parameters_.path);
    report_.from_database = path.ok;
    report_.poses = static_cast<int>(stored->blades.size());
    source << (path.ok ? "stored path adapted" : "solved in full: no pose of the stored path fits");
    source << " (stored target " << distance << " m off)";
  }
  report_.database_distance = stored != nullptr ? distance : -1.0;
  report_.path_source = source.str();
  if (!path.ok) {
    const std::vector<Eigen::Isometry3d> poses = CuttingPoses(blade_surface, parameters_.poses);
    report_.poses = static_cast<int>(poses.size());
    path =
        PlanCuttingPath(kinematics_, T_cutter_blade_, start, poses, checks.valid, checks.free_move, parameters_.path);
    report_.nearest_neighbour_time = path.nearest_neighbour_time;
  }
  if (!path.ok) {
    Finish(stamp, "no cutting path: " + path.failure);
    return;
  }
  report_.reached = static_cast<int>(path.poses.size());
  for (const Eigen::Isometry3d& blade : path.blades) {
    report_.unseen += LeavesSeenOver((blade.translation() - target.centre).normalized()) ? 0 : 1;
  }
  report_.motion_time = path.motion_time;
  const std::vector<Eigen::VectorXd> waypoints = Waypoints(path, checks, &failure);
  report_.planning_seconds += SecondsSince(begin);
  if (waypoints.empty()) {
    Finish(stamp, failure);
    return;
  }
  Eigen::VectorXd limits(kinematics_.joints());
  for (int i = 0; i < kinematics_.joints(); ++i) {
    limits(i) = parameters_.planner.velocity_scale * kinematics_.limits()[static_cast<std::size_t>(i)].velocity;
  }
  trajectory_ = arm::TimeParameterize(waypoints, limits, parameters_.planner.acceleration, stops_);
  report_.cutting_duration = trajectory_.duration();
  // The arm stops at the first and the last blade waypoint: the parts' durations add up.
  const auto duration = [&](std::size_t from, std::size_t to) {
    const auto begin = static_cast<std::ptrdiff_t>(from), end = static_cast<std::ptrdiff_t>(to) + 1;
    return arm::TimeParameterize({waypoints.begin() + begin, waypoints.begin() + end}, limits,
                                 parameters_.planner.acceleration, {stops_.begin() + begin, stops_.begin() + end})
        .duration();
  };
  cut_begins_ = duration(0, first_blade_waypoint_);
  cut_ends_ = trajectory_.duration() - duration(last_blade_waypoint_, waypoints.size() - 1);
  motion_start_ = stamp;
  target_ = trajectory_.positions.front();
  mode_ = Mode::kCutting;
}

std::vector<Eigen::VectorXd> TrimExecutive::Waypoints(const CuttingPath& path, const CuttingChecks& checks,
                                                      std::string* failure) {
  const std::vector<Eigen::VectorXd>& q = path.configurations;  // the start, the blade poses, the start
  const std::size_t last = q.size() - 2;                        // the last blade pose
  // In round the leaves to the first blade pose that has such a way, out from the last: the poses before and
  // after those are left out (a blade pose hard against the base cannot be drawn back along its axis), at most
  // kMaxLeftOut at either end; beyond that the move goes round the shrunk target as any planned move does.
  constexpr std::size_t kMaxLeftOut = 3;
  const auto way_round = [&](std::size_t k) {
    return IntoTheLeaves(q.front(), q.front() + kinematics_.JointDifference(q.front(), q[k]));
  };
  std::size_t first = 1, final = last;
  std::vector<Eigen::VectorXd> in, out;
  for (std::size_t k = 1; k <= std::min(last, 1 + kMaxLeftOut) && in.empty(); ++k) {
    in = way_round(k);
    if (!in.empty()) first = k;
  }
  for (std::size_t k = last; k >= first && k + kMaxLeftOut >= last && out.empty(); --k) {
    out = k == first && !in.empty() ? in : way_round(k);  // the way in, when it is the one pose left
    if (!out.empty()) final = k;
    if (k == first) break;
  }
  report_.left_out = static_cast<int>((first - 1) + (last - final));
  std::vector<Eigen::VectorXd> waypoints{q.front()};
  stops_ = {true};
  const auto append = [&](const std::vector<Eigen::VectorXd>& way) {  // stopping at each of its waypoints
    waypoints.insert(waypoints.end(), way.begin() + 1, way.end());
    stops_.resize(waypoints.size(), true);
  };
  const auto along = [&](const std::vector<Eigen::VectorXd>& line) {  // a free move: stopping at its end only
    waypoints.insert(waypoints.end(), line.begin(), line.end());
    stops_.resize(waypoints.size(), false);
    stops_.back() = true;
  };
  const auto plan_round_target = [&](const Eigen::VectorXd& to, std::size_t pose) {
    const arm::ArmPlan plan = planner_->PlanToJoints(waypoints.back(), to);
    if (!plan.ok) {
      *failure = "no move round the target from blade pose " + std::to_string(pose) + " to the next: " + plan.failure;
      return false;
    }
    append(plan.waypoints);
    ++report_.planned_moves;
    return true;
  };
  if (!in.empty()) {
    append(in);
    ++report_.moves_round_the_leaves;
  } else if (!plan_round_target(q.front() + kinematics_.JointDifference(q.front(), q[first]), 0)) {
    return {};
  }
  first_blade_waypoint_ = waypoints.size() - 1;
  for (std::size_t i = first; i < final; ++i) {
    const Eigen::VectorXd to = waypoints.back() + kinematics_.JointDifference(waypoints.back(), q[i + 1]);
    // A free move (the checks' way) that keeps the blade's turn and its tilt off the surface small stays in the
    // swath it cuts; any other goes out along the axis, round the leaves and in (where it can), not through them.
    const std::vector<Eigen::VectorXd> move =
        path.planned[i] ? std::vector<Eigen::VectorXd>{} : checks.way(waypoints.back(), to);
    const bool in_swath =
        !move.empty() && BladeTurn(waypoints.back(), to) <= MaxTurnInLeaves() && MaxTilt(move) <= MaxTurnInLeaves();
    const std::vector<Eigen::VectorXd> way =
        in_swath ? std::vector<Eigen::VectorXd>{} : RoundTheLeaves(waypoints.back(), to);
    if (!way.empty()) {
      append(way);
      ++report_.turns_round_the_leaves;
    } else if (!move.empty()) {
      along(move);
    } else if (!plan_round_target(to, i)) {
      return {};
    }
  }
  last_blade_waypoint_ = waypoints.size() - 1;
  if (!out.empty()) {
    append(BeginningAt({out.rbegin(), out.rend()}, waypoints.back()));
    ++report_.moves_round_the_leaves;
  } else if (!plan_round_target(waypoints.back() + kinematics_.JointDifference(waypoints.back(), q.back()), final)) {
    return {};
  }
  return waypoints;
}

std::vector<Eigen::VectorXd> TrimExecutive::DrawnBack(const Eigen::VectorXd& at_blade) {
  // From blade_depth inside the fit to leaf_clearance beyond the leaves' depth, and the disc's
  // thickness.
  const Eigen::Isometry3d cutter = kinematics_.EndEffectorPose(at_blade);
  const Eigen::Vector3d into = cutter.linear() * T_cutter_blade_.linear().col(2);
  constexpr double kDiscClearance = 0.01;  // m
  Eigen::Isometry3d back = cutter;
  back.translation() -=
      (parameters_.blade_depth + report_.leaf_depth + parameters_.leaf_clearance + kDiscClearance) * into;
  const arm::ArmPlan pass = planner_->CartesianPass(at_blade, back);  // within the shrunk target's
  return pass.ok ? pass.waypoints : std::vector<Eigen::VectorXd>{};
}

std::vector<Eigen::VectorXd> TrimExecutive::IntoTheLeaves(const Eigen::VectorXd& outside,
                                                          const Eigen::VectorXd& at_blade) {
  const std::vector<Eigen::VectorXd> drawn_back = DrawnBack(at_blade);
  if (drawn_back.empty()) return {};
  SetTargetEnvironment(collision_.get(), target_shape_, report_.leaf_depth + parameters_.leaf_clearance);
  planner_->ResetRoadmap();
  const arm::ArmPlan round = planner_->PlanToJoints(outside, drawn_back.back());
  SetTargetEnvironment(collision_.get(), target_shape_, -check_depth_);
  planner_->ResetRoadmap();
  if (!round.ok) return {};
  std::vector<Eigen::VectorXd> way = round.waypoints;
  const std::vector<Eigen::VectorXd> in = BeginningAt({drawn_back.rbegin(), drawn_back.rend()}, way.back());
  way.insert(way.end(), in.begin() + 1, in.end());
  return way;
}

std::vector<Eigen::VectorXd> TrimExecutive::RoundTheLeaves(const Eigen::VectorXd& from, const Eigen::VectorXd& to) {
  std::vector<Eigen::VectorXd> way = DrawnBack(from);
  if (way.empty()) return {};
  const std::vector<Eigen::VectorXd> in = IntoTheLeaves(way.back(), to);
  if (in.empty()) return {};
  way.insert(way.end(), in.begin() + 1, in.end());
  return way;
}

double TrimExecutive::MaxTurnInLeaves() const {
  const double height = parameters_.blade_depth + report_.leaf_depth;
  return height > blade_radius_ - housing_radius_ ? std::asin((blade_radius_ - housing_radius_) / height) : M_PI;
}

bool TrimExecutive::ArmInLeaves(const Eigen::VectorXd& q) const {
  const std::vector<Eigen::Isometry3d> poses = kinematics_.LinkPoses(q);
  for (const auto& [index, cylinder] : arm_links_) {
    const Eigen::Vector3d a = poses[index] * cylinder.a, b = poses[index] * cylinder.b;
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.01)));
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector3d p = a + (b - a) * (static_cast<double>(k) / steps);
      if (target_shape_.RadialDistance(p) < report_.leaf_depth + cylinder.radius) return true;
    }
  }
  return false;
}

double TrimExecutive::MaxTilt(const std::vector<Eigen::VectorXd>& way) const {
  double tilt = 0.0;
  for (const Eigen::VectorXd& q : way) {
    const Eigen::Isometry3d blade = kinematics_.EndEffectorPose(q) * T_cutter_blade_;
    const Eigen::Vector3d inward = -SurfaceNormal(target_shape_, blade.translation());
    tilt = std::max(tilt, std::acos(std::clamp(inward.dot(blade.linear().col(2)), -1.0, 1.0)));
  }
  return tilt;
}

bool TrimExecutive::LeavesSeenOver(const Eigen::Vector3d& direction) const {
  const Eigen::Isometry3d on_fit = BladePoseAt(target_shape_, direction);
  const Eigen::Vector3d n = -on_fit.linear().col(2);
  const int needed = static_cast<int>(std::ceil(1.0 / parameters_.fit.quantile - 1e-9));
  int count = 0;
  for (const Eigen::Vector3d& p : leaves_) {
    const Eigen::Vector3d v = p - on_fit.translation();
    const double along = v.dot(n);
    if (std::abs(along) <= parameters_.scan_margin && (v - along * n).norm() <= blade_radius_ && ++count >= needed) {
      return true;
    }
  }
  return false;
}

double TrimExecutive::BladeTurn(const Eigen::VectorXd& from, const Eigen::VectorXd& to) const {
  const Eigen::Vector3d a = (kinematics_.EndEffectorPose(from) * T_cutter_blade_).linear().col(2);
  const Eigen::Vector3d b = (kinematics_.EndEffectorPose(to) * T_cutter_blade_).linear().col(2);
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0));
}

void TrimExecutive::Finish(double stamp, const std::string& failure) {
  report_.failure = failure;
  report_.end = stamp;
  mode_ = Mode::kDone;
}

}  // namespace trimbot::trimming
