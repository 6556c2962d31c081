// The robot's navigation on its prior map: occupancy grid and distances, OMPL planning around
// obstacles, path following on a simulated unicycle, goal-to-goal navigation with the obstacle stop.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Geometry>

#include "trimbot/common/input_error.h"
#include "trimbot/stack/bush_servo.h"
#include "trimbot/stack/global_planner.h"
#include "trimbot/stack/navigator.h"
#include "trimbot/stack/occupancy_grid.h"
#include "trimbot/stack/path_follower.h"

namespace trimbot::stack {
namespace {

// 10 x 8 m map at 5 cm, origin (0, 0), with a wall x in [4.8, 5.2], y in [0, 6] (a gap above y = 6).
OccupancyGrid WallMap() {
  const double resolution = 0.05;
  cv::Mat occupied(160, 200, CV_8U, cv::Scalar(0));
  for (int r = 0; r < occupied.rows; ++r) {
    for (int c = 0; c < occupied.cols; ++c) {
      const double x = (c + 0.5) * resolution, y = (occupied.rows - 1 - r + 0.5) * resolution;
      if (x > 4.8 && x < 5.2 && y < 6.0) occupied.at<uchar>(r, c) = 255;
    }
  }
  return OccupancyGrid(occupied, resolution, {0.0, 0.0});
}

// The URDF's base outline (chassis 0.70 m long from x = -0.12, wheels' outer faces at +-0.255 m).
const BaseOutline kOutline({-0.12, -0.255}, {0.58, 0.255});

// A differential-drive base that does exactly what it is told.
Pose2 Integrate(const Pose2& pose, const messages::BaseVelocityCommand& command, double dt) {
  Pose2 next = pose;
  next.x += command.linear * std::cos(pose.yaw) * dt;
  next.y += command.linear * std::sin(pose.yaw) * dt;
  next.yaw = std::remainder(pose.yaw + command.angular * dt, 2.0 * M_PI);
  return next;
}

TEST(OccupancyGrid, DistanceToTheNearestObstacle) {
  const OccupancyGrid map = WallMap();
  EXPECT_NEAR(map.DistanceToObstacle({3.8, 3.0}), 1.0, 0.04);
  EXPECT_NEAR(map.DistanceToObstacle({6.2, 2.0}), 1.0, 0.04);
  EXPECT_EQ(map.DistanceToObstacle({5.0, 3.0}), 0.0);
  EXPECT_EQ(map.DistanceToObstacle({-1.0, 3.0}), 0.0) << "outside the map counts as occupied";
  const cv::Point cell = map.Cell({5.0, 3.0});
  EXPECT_NEAR(map.CellCentre(cell).x(), 5.0, 0.03);
  EXPECT_NEAR(map.CellCentre(cell).y(), 3.0, 0.03);
}

TEST(OccupancyGrid, LoadsMapServerFilesAndNamesTheFileOnErrors) {
  const std::string dir = ::testing::TempDir() + "/map_server_test";
  std::filesystem::create_directories(dir);
  cv::Mat image(40, 60, CV_8U, cv::Scalar(254));
  image(cv::Rect(10, 10, 5, 5)).setTo(0);  // black = occupied
  cv::imwrite(dir + "/m.png", image);
  std::ofstream(dir + "/m.yaml") << "image: m.png\nresolution: 0.1\norigin: [-1.0, -2.0, 0.0]\nnegate: 0\n"
                                    "occupied_thresh: 0.65\nfree_thresh: 0.196\n";
  const OccupancyGrid map = OccupancyGrid::LoadMapServer(dir + "/m.yaml");
  EXPECT_EQ(map.occupied().cols, 60);
  EXPECT_NEAR(map.origin().y(), -2.0, 1e-12);
  // Cell (12, 12) from the top is occupied: x = -1 + 1.25, y = -2 + (40 - 12.5) * 0.1.
  EXPECT_EQ(map.DistanceToObstacle({0.25, 0.75}), 0.0);
  EXPECT_GT(map.DistanceToObstacle({4.0, 1.5}), 2.0);

  std::ofstream(dir + "/bad.yaml") << "image: missing.png\nresolution: 0.1\norigin: [0, 0, 0]\n";
  try {
    OccupancyGrid::LoadMapServer(dir + "/bad.yaml");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos) << e.what();
  }
  std::ofstream(dir + "/typo.yaml") << "image: m.png\nresolution: 0.1\norigin: [0, 0, 0]\nresolutoin: 2\n";
  try {
    OccupancyGrid::LoadMapServer(dir + "/typo.yaml");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("typo.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("resolutoin"), std::string::npos) << e.what();
  }
}

TEST(GlobalPlanner, PlansAroundAWallKeepingTheClearance) {
  SeedPlanner(7);
  const OccupancyGrid map = WallMap();
  const GlobalPlanner planner(map, kOutline, PlannerParameters{});
  const PlanResult plan = planner.Plan({2.0, 2.0, 0.0}, {8.0, 2.0}, 0.025);
  ASSERT_TRUE(plan.found) << plan.message;
  EXPECT_NEAR((plan.path.front() - Eigen::Vector2d(2.0, 2.0)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((plan.path.back() - Eigen::Vector2d(8.0, 2.0)).norm(), 0.0, 0.05);
  // Around the end of the wall at y = 6 and back: at least 2 * hypot(3, 4.5) long.
  EXPECT_GT(plan.length, 2.0 * std::hypot(3.0, 4.0));
  EXPECT_LT(plan.length, 13.0) << "a detour far beyond the gap";
  bool went_over_the_wall = false;
  for (std::size_t i = 1; i < plan.path.size(); ++i) {
    const Eigen::Vector2d d = plan.path[i] - plan.path[i - 1];
    const double heading = std::atan2(d.y(), d.x());
    for (double f = 0.0; f <= 1.0; f += 0.02) {
      const Eigen::Vector2d p = plan.path[i - 1] + f * d;
      // The outline driving the segment keeps the clearance (less the half step between checks).
      EXPECT_GE(planner.Clearance({p.x(), p.y(), heading}), planner.parameters().min_clearance - 0.0125)
          << p.transpose();
      went_over_the_wall = went_over_the_wall || (std::abs(p.x() - 5.0) < 0.3 && p.y() > 6.0);
    }
  }
  EXPECT_TRUE(went_over_the_wall);
}

TEST(GlobalPlanner, ReportsUnreachableAndBlockedGoals) {
  SeedPlanner(7);
  cv::Mat occupied(100, 100, CV_8U, cv::Scalar(0));
  cv::rectangle(occupied, cv::Rect(60, 20, 30, 30), cv::Scalar(255), 2);  // a closed box
  const OccupancyGrid map(occupied, 0.05, {0.0, 0.0});
  PlannerParameters parameters;
  parameters.iterations = 500;
  const GlobalPlanner planner(map, kOutline, parameters);
  const Eigen::Vector2d inside_box(3.75, 3.25);
  ASSERT_TRUE(planner.FreeHeading(inside_box).has_value());
  const PlanResult enclosed = planner.Plan({1.0, 1.0, 0.0}, inside_box, 0.025);
  EXPECT_FALSE(enclosed.found);
  EXPECT_FALSE(enclosed.message.empty());
  const PlanResult on_wall = planner.Plan({1.0, 1.0, 0.0}, {3.0, 2.5}, 0.025);
  EXPECT_FALSE(on_wall.found);
  EXPECT_NE(on_wall.message.find("goal"), std::string::npos) << on_wall.message;
}

TEST(PathFollower, DrivesAnLShapedPathTurningOnTheSpotAtTheCorner) {
  PathFollower follower(FollowerParameters{});
  follower.SetPath({{0.0, 0.0}, {3.0, 0.0}, {3.0, 2.0}});
  Pose2 pose{0.0, 0.0, 0.0};
  double worst_deviation = 0.0, top_speed = 0.0;
  bool arrived = false;
  for (int k = 0; k < 4000 && !arrived; ++k) {
    const FollowerOutput out = follower.Update(pose);
    arrived = out.arrived;
    worst_deviation = std::max(worst_deviation, out.deviation);
    top_speed = std::max(top_speed, out.command.linear);
    pose = Integrate(pose, out.command, 0.05);
  }
  ASSERT_TRUE(arrived);
  EXPECT_LT(std::hypot(pose.x - 3.0, pose.y - 2.0), 0.08);
  // Within the sharp-vertex tolerance of the path everywhere: a cut corner would be ~0.2 m off.
  EXPECT_LT(worst_deviation, FollowerParameters{}.vertex_tolerance + 0.01) << "the corner was cut";
  EXPECT_NEAR(top_speed, 0.25, 1e-9);
}

// Segments planned close to obstacles are driven as planned: set off lined up (not within the
// usual 0.15 rad), to the vertex and turn there (not cut, though the turn is below sharp_turn).
// The same path with room to spare is driven the usual way, cutting that corner.
TEST(PathFollower, DrivesTightSegmentsAsPlanned) {
  const std::vector<Eigen::Vector2d> path{{0.0, 0.0}, {2.0, 0.0}, {4.0, 0.6}};
  const auto drive = [&](const std::vector<double>& clearance) {
    PathFollower follower(FollowerParameters{});
    follower.SetPath(path, clearance);
    Pose2 pose{0.0, 0.0, 0.12};  // within align_tolerance of the path
    double worst = 0.0;
    bool arrived = false;
    for (int k = 0; k < 4000 && !arrived; ++k) {
      const FollowerOutput out = follower.Update(pose);
      arrived = out.arrived;
      worst = std::max(worst, out.deviation);
      pose = Integrate(pose, out.command, 0.05);
    }
    EXPECT_TRUE(arrived);
    return worst;
  };
  const double tight = drive({0.05, 0.05}), roomy = drive({});
  EXPECT_LT(tight, 0.01) << "the tight path was left";
  EXPECT_GT(roomy, 0.02) << "the roomy path was driven exactly: the comparison shows nothing";
  PathFollower follower(FollowerParameters{});
  EXPECT_THROW(follower.SetPath(path, {0.05}), std::invalid_argument);
}

// Goals with a heading are arrived at facing it (a turn on the spot where the path ends, lined up
// within exact_align_tolerance); a goal whose heading puts the outline into the wall moves to the
// nearest position where the outline fits at that heading (reported), not to another heading.
TEST(Navigator, ArrivesAtAGoalsHeading) {
  SeedPlanner(5);
  const OccupancyGrid map = WallMap();
  Navigator navigator(map, kOutline, NavigatorParameters{});
  const std::vector<NavigationGoal> goals{{Eigen::Vector2d(8.0, 2.0), M_PI / 2},
                                          {Eigen::Vector2d(2.0, 1.5), M_PI},
                                          {Eigen::Vector2d(4.3, 3.0), 0.0}};  // the base's front 0.08 m into the wall
  navigator.SetGoals(goals);
  Pose2 pose{2.0, 2.0, 0.0};
  std::vector<Pose2> arrivals;
  double adjusted = 0.0;
  for (double t = 0.0; t < 600.0 && navigator.mode() != Navigator::Mode::kDone; t += 0.05) {
    pose = Integrate(pose, navigator.Update(t, pose), 0.05);
    for (const auto& e : navigator.TakeEvents()) {
      if (e.type == NavigationEvent::Type::kGoalReached) arrivals.push_back(pose);
      if (e.type == NavigationEvent::Type::kGoalAdjusted) adjusted = (e.position - goals[2].position).norm();
    }
  }
  ASSERT_EQ(navigator.mode(), Navigator::Mode::kDone);
  ASSERT_EQ(arrivals.size(), 3u);
  const double tolerance = FollowerParameters{}.exact_align_tolerance;
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(std::remainder(arrivals[i].yaw - *goals[i].yaw, 2.0 * M_PI)), tolerance) << "goal " << i;
  }
  EXPECT_LT((Eigen::Vector2d(arrivals[0].x, arrivals[0].y) - goals[0].position).norm(), 0.1);
  // At heading 0 the outline's front (0.58 m ahead) keeps min_clearance from the wall at x 4.8
  // only from 4.8 - 0.58 - min_clearance back: the goal moves at least that far (and by less than
  // the search radius), not to another heading.
  EXPECT_GE(adjusted, 4.3 - (4.8 - kOutline.max().x() - NavigatorParameters{}.planner.min_clearance) - 1e-9);
  EXPECT_LT(adjusted, NavigatorParameters{}.goal_search_radius);
  EXPECT_LT(arrivals[2].x + kOutline.max().x(), 4.8 - 0.05);
}

// Backing off after an obstacle stop undoes the way the robot came: it drove east, turned on the
// spot to face north and drove on; stopped by a wall seen just ahead, it backs down to where it
// turned, turns back and reverses west, where straight back would leave the way it came (and
// sweep what it never swept) going south.
TEST(Navigator, BacksOffTheWayItCame) {
  SeedPlanner(3);
  const OccupancyGrid map = WallMap();
  Navigator navigator(map, kOutline, NavigatorParameters{});
  navigator.SetGoals({Eigen::Vector2d(3.5, 1.0)});
  // The way it came (the estimate, whatever the commands): 0.5 m east, a quarter turn, 0.1 m north.
  std::vector<Pose2> way;
  for (double x = 1.0; x <= 1.5 + 1e-9; x += 0.01) way.push_back({x, 1.0, 0.0});
  for (double yaw = 0.0; yaw <= M_PI / 2 + 1e-9; yaw += 0.02) way.push_back({1.5, 1.0, yaw});
  for (double y = 1.0; y <= 1.1 + 1e-9; y += 0.01) way.push_back({1.5, y, M_PI / 2});
  double t = 0.0;
  for (const Pose2& p : way) {
    navigator.Update(t, p);
    t += 0.05;
  }
  ASSERT_EQ(navigator.mode(), Navigator::Mode::kFollowing);
  // A wall seen 2 cm ahead of the outline's front, across the way.
  cv::Mat occupied = map.occupied().clone();
  const Pose2 end = way.back();
  const double wall_y = end.y + kOutline.max().x() + 0.02;
  for (int r = 0; r < occupied.rows; ++r) {
    for (int c = 0; c < occupied.cols; ++c) {
      const Eigen::Vector2d p = map.CellCentre({c, r});
      if (p.y() >= wall_y + 0.5 * map.resolution() && p.y() < wall_y + 0.3 && std::abs(p.x() - 1.5) < 1.0) {
        occupied.at<uchar>(r, c) = 255;
      }
    }
  }
  navigator.SetCostmap(OccupancyGrid(occupied, map.resolution(), map.origin()));
  Pose2 pose = end;
  double lowest = pose.y;
  bool stopped = false;
  for (int k = 0; k < 400 && (!stopped || navigator.mode() == Navigator::Mode::kBackingOff); ++k, t += 0.05) {
    pose = Integrate(pose, navigator.Update(t, pose), 0.05);
    stopped = stopped || navigator.mode() == Navigator::Mode::kBackingOff;
    if (stopped) lowest = std::min(lowest, pose.y);
  }
  ASSERT_TRUE(stopped) << "no obstacle stop";
  EXPECT_NE(navigator.mode(), Navigator::Mode::kBackingOff);
  EXPECT_GT(lowest, 1.0 - 0.02) << "backed off south of the way it came";
  EXPECT_LT(pose.yaw, M_PI / 2 - 0.2) << "did not turn back where it had turned";
  // Facing north (as it stopped) the wall stays as near on the way back west: it ends after
  // max_backoff, on the way it came.
  EXPECT_NEAR(pose.y, 1.0, 0.03);
  EXPECT_LT(pose.x, 1.5 + 0.03);
}

TEST(Navigator, VisitsGoalsInOrderAndStopsAndBacksOffNearAnObstacle) {
  SeedPlanner(11);
  const OccupancyGrid map = WallMap();
  Navigator navigator(map, kOutline, NavigatorParameters{});
  navigator.SetGoals({Eigen::Vector2d(8.0, 2.0), Eigen::Vector2d(2.0, 1.5)});
  Pose2 pose{2.0, 2.0, M_PI / 2};
  std::vector<NavigationEvent> events;
  double t = 0.0;
  double closest = 1e9;
  for (; t < 400.0 && navigator.mode() != Navigator::Mode::kDone; t += 0.05) {
    pose = Integrate(pose, navigator.Update(t, pose), 0.05);
    closest = std::min(closest, navigator.OutlineClearance(pose));
    for (const auto& e : navigator.TakeEvents()) events.push_back(e);
  }
  ASSERT_EQ(navigator.mode(), Navigator::Mode::kDone);
  int reached = 0;
  for (const auto& e : events) reached += e.type == NavigationEvent::Type::kGoalReached ? 1 : 0;
  EXPECT_EQ(reached, 2);
  EXPECT_LT(std::hypot(pose.x - 2.0, pose.y - 1.5), 0.1);
  EXPECT_GT(closest, 0.03) << "the outline came closer to the wall than the stop distance";

  // Driving north along the wall, 0.5 m from it, the estimate jumps 0.45 m towards the wall (a
  // re-localization): the outline now overlaps it while moving - stop, back off.
  Navigator stopper(map, kOutline, NavigatorParameters{});
  stopper.SetGoals({Eigen::Vector2d(4.3, 5.5)});
  Pose2 truth{4.3, 1.0, M_PI / 2};
  bool stopped = false, backed = false;
  for (int k = 0; k < 400 && !backed; ++k) {
    Pose2 estimate = truth;
    if (k >= 100) estimate.x += 0.45;
    const auto command = stopper.Update(k * 0.05, estimate);
    for (const auto& e : stopper.TakeEvents()) stopped = stopped || e.type == NavigationEvent::Type::kObstacleStop;
    backed = command.linear < 0.0;
    EXPECT_FALSE(k < 100 && stopped) << "stopped before the jump";
    truth = Integrate(truth, command, 0.05);
  }
  EXPECT_TRUE(stopped);
  EXPECT_TRUE(backed);
}

// Drives `navigator` on a perfect unicycle from `pose` until it is done or failed (or 300 s), and
// returns its events; `on_step(t, pose)` runs before each update.
template <typename OnStep>
std::vector<NavigationEvent> DriveUntilDone(Navigator& navigator, Pose2& pose, OnStep on_step) {
  std::vector<NavigationEvent> events;
  for (double t = 0.0; t < 300.0; t += 0.05) {
    const Navigator::Mode mode = navigator.mode();
    if (mode == Navigator::Mode::kDone || mode == Navigator::Mode::kFailed) break;
    on_step(t, pose);
    pose = Integrate(pose, navigator.Update(t, pose), 0.05);
    for (const auto& e : navigator.TakeEvents()) events.push_back(e);
  }
  return events;
}

int Count(const std::vector<NavigationEvent>& events, NavigationEvent::Type type) {
  return static_cast<int>(
      std::count_if(events.begin(), events.end(), [type](const auto& e) { return e.type == type; }));
}

// An obstacle the prior map lacks appears on the path (perception's costmap): the navigator plans
// again and goes around it, its outline never touching the box.
TEST(Navigator, PlansAgainWhenASeenObstacleBlocksThePath) {
  SeedPlanner(12);
  const OccupancyGrid map = WallMap();
  Navigator navigator(map, kOutline, NavigatorParameters{});
  navigator.SetGoals({Eigen::Vector2d(3.8, 7.0)});
  Pose2 pose{3.8, 0.8, M_PI / 2};
  const Eigen::Vector2d box(3.8, 4.0);  // 0.4 m square, on the straight line to the goal
  cv::Mat occupied = map.occupied().clone();
  for (double x = box.x() - 0.2; x <= box.x() + 0.2; x += 0.025) {
    for (double y = box.y() - 0.2; y <= box.y() + 0.2; y += 0.025) occupied.at<uchar>(map.Cell({x, y})) = 255;
  }
  const OccupancyGrid seen_map(occupied, map.resolution(), map.origin());
  bool seen = false;
  double closest = 1e9;
  int step = 0;
  const auto events = DriveUntilDone(navigator, pose, [&](double, const Pose2& p) {
    // Seen 2.5 m ahead, as stereo would; then the same costmap again at 2.5 Hz (nothing new).
    if (p.y > 1.5 && (!seen || ++step % 8 == 0)) {
      navigator.SetCostmap(OccupancyGrid(occupied, map.resolution(), map.origin()));
      seen = true;
    }
    closest = std::min(closest, kOutline.Clearance(seen_map, p));
  });
  EXPECT_EQ(navigator.mode(), Navigator::Mode::kDone);
  EXPECT_EQ(Count(events, NavigationEvent::Type::kPathBlocked), 1) << "blocked once, then planned around";
  EXPECT_EQ(Count(events, NavigationEvent::Type::kGoalReached), 1);
  EXPECT_GT(closest, NavigatorParameters{}.stop_clearance) << "the outline came within " << closest << " m of the box";
  EXPECT_LT(std::hypot(pose.x - 3.8, pose.y - 7.0), 0.1);
}

// A goal 0.3 m from a wall, where the base fits beside the wall with 4.5 cm to spare (less than
// the planner's 5 cm): reached within a cell or two of where it was asked. A goal inside the wall is
// moved to the nearest position where the outline fits (0.5 m out), and refused with the reason
// when goal_search_radius does not reach that far.
TEST(Navigator, GoalNearAnObstacleIsReachedWhereTheOutlineFits) {
  SeedPlanner(13);
  const OccupancyGrid map = WallMap();
  const NavigatorParameters parameters;
  const auto drive_to = [&](const Eigen::Vector2d& goal, const NavigatorParameters& p, Navigator::Mode* mode,
                            Pose2* end) {
    Navigator navigator(map, kOutline, p);
    navigator.SetGoals({goal});
    *end = {1.5, 3.0, 0.0};
    const auto events = DriveUntilDone(navigator, *end, [](double, const Pose2&) {});
    *mode = navigator.mode();
    return events;
  };
  const auto adjusted_to = [](const std::vector<NavigationEvent>& events) -> std::optional<Eigen::Vector2d> {
    for (const auto& e : events) {
      if (e.type == NavigationEvent::Type::kGoalAdjusted) return e.position;
    }
    return std::nullopt;
  };
  Navigator::Mode mode;
  Pose2 end;
  const Eigen::Vector2d beside(4.5, 3.0);  // the wall starts at x = 4.8
  auto events = drive_to(beside, parameters, &mode, &end);
  for (const auto& e : events) std::printf("%.2f %s %s\n", e.stamp, ToString(e.type), e.detail.c_str());
  ASSERT_EQ(mode, Navigator::Mode::kDone);
  const Eigen::Vector2d used = adjusted_to(events).value_or(beside);
  EXPECT_LT((used - beside).norm(), 0.1);
  // Arrival is judged within the follower's goal_tolerance of the path's end, which is within half
  // a cell of the goal planned to; the last step of 0.05 s may carry it 1.25 cm further.
  const double arrival =
      parameters.follower.goal_tolerance + 0.5 * map.resolution() + 0.05 * parameters.follower.cruise_speed;
  EXPECT_LE(std::hypot(end.x - used.x(), end.y - used.y()), arrival);
  EXPECT_GE(kOutline.Clearance(map, end), 0.0);

  const Eigen::Vector2d in_the_wall(5.0, 3.0);
  events = drive_to(in_the_wall, parameters, &mode, &end);
  ASSERT_EQ(mode, Navigator::Mode::kDone);
  const auto moved = adjusted_to(events);
  ASSERT_TRUE(moved.has_value());
  // Straight back from the wall: base_link 0.255 + 0.05 m from its face at x = 4.8 (to a cell).
  EXPECT_NEAR(moved->x(), 4.8 - 0.255 - 0.05, 0.06);
  EXPECT_NEAR(moved->y(), 3.0, 0.06);

  NavigatorParameters strict = parameters;
  strict.goal_search_radius = 0.3;
  events = drive_to(in_the_wall, strict, &mode, &end);
  EXPECT_EQ(mode, Navigator::Mode::kFailed);
  EXPECT_EQ(Count(events, NavigationEvent::Type::kGoalAdjusted), 0);
  const auto failed = std::find_if(events.begin(), events.end(),
                                   [](const auto& e) { return e.type == NavigationEvent::Type::kGoalFailed; });
  ASSERT_NE(failed, events.end());
  EXPECT_NE(failed->detail.find("fits nowhere"), std::string::npos) << failed->detail;
}

// A gap between two walls 0.2 m wider than the base is passed; one 0.05 m narrower than the base
// is refused, with the reason, and never driven into.
TEST(GlobalPlanner, PassesAGapWiderThanTheBaseAndRefusesANarrowerOne) {
  for (const double extra : {0.2, -0.05}) {
    SeedPlanner(14);
    const double gap = kOutline.width() + extra;
    // A wall across x in [2.0, 2.4] with a gap centred on y = 3 (map 6 x 6 m).
    cv::Mat occupied(120, 120, CV_8U, cv::Scalar(0));
    const OccupancyGrid empty(occupied, 0.05, {0.0, 0.0});
    for (int row = 0; row < occupied.rows; ++row) {
      for (int column = 0; column < occupied.cols; ++column) {
        const Eigen::Vector2d c = empty.CellCentre({column, row});
        if (c.x() > 2.0 && c.x() < 2.4 && std::abs(c.y() - 3.0) > 0.5 * gap) occupied.at<uchar>(row, column) = 255;
      }
    }
    const OccupancyGrid map(occupied, 0.05, {0.0, 0.0});
    PlannerParameters parameters;
    parameters.iterations = 3000;
    const GlobalPlanner planner(map, kOutline, parameters);
    const PlanResult plan = planner.Plan({0.8, 2.0, 0.0}, {4.0, 4.0}, 0.025);
    if (extra > 0.0) {
      ASSERT_TRUE(plan.found) << "gap " << gap << " m: " << plan.message;
      for (std::size_t i = 1; i < plan.path.size(); ++i) {
        const Eigen::Vector2d d = plan.path[i] - plan.path[i - 1];
        for (double f = 0.0; f <= 1.0; f += 0.01) {
          const Eigen::Vector2d p = plan.path[i - 1] + f * d;
          EXPECT_GE(planner.Clearance({p.x(), p.y(), std::atan2(d.y(), d.x())}), 0.0) << p.transpose();
        }
      }
    } else {
      EXPECT_FALSE(plan.found) << "gap " << gap << " m narrower than the base";
      EXPECT_FALSE(plan.message.empty());
    }
  }
}

// A gap 0.15 m wider than the base (2.5 cm to spare a side beyond the 5 cm walls) in a wall at 30
// degrees to the map's axes: the 0.7 m long base fits through it only lined up within 2 degrees,
// which a sampling planner rarely hits; the grid route, pulled taut where its motions cut in at an
// angle and backing up where a vertex leaves no room to turn into the gap, passes it whatever the
// seed. The plan reports its clearance per segment, the gap's below the follower's exact_below.
TEST(GlobalPlanner, PassesATightGapAtAnAngleWhateverTheSeed) {
  const double gap = kOutline.width() + 0.15;
  const Eigen::Vector2d centre(3.0, 3.0), along(std::cos(M_PI / 6), std::sin(M_PI / 6)), across(-along.y(), along.x());
  cv::Mat occupied(120, 120, CV_8U, cv::Scalar(0));
  const OccupancyGrid empty(occupied, 0.05, {0.0, 0.0});
  for (int row = 0; row < occupied.rows; ++row) {
    for (int column = 0; column < occupied.cols; ++column) {
      const Eigen::Vector2d d = empty.CellCentre({column, row}) - centre;
      // The cells' squares keep out of the gap: their centres a half square's extent further out.
      const double square = 0.5 * 0.05 * (std::abs(across.x()) + std::abs(across.y()));
      if (std::abs(d.dot(along)) < 0.2 && std::abs(d.dot(across)) > 0.5 * gap + square) {
        occupied.at<uchar>(row, column) = 255;
      }
    }
  }
  const OccupancyGrid map(occupied, 0.05, {0.0, 0.0});
  PlannerParameters parameters;
  parameters.iterations = 3000;
  const GlobalPlanner planner(map, kOutline, parameters);
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    SeedPlanner(seed);
    const PlanResult plan = planner.Plan({1.0, 3.5, 0.0}, {5.0, 2.5}, 0.025);
    ASSERT_TRUE(plan.found) << "seed " << seed << ": " << plan.message;
    ASSERT_EQ(plan.clearance.size() + 1, plan.path.size());
    double tightest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 1; i < plan.path.size(); ++i) {
      const Eigen::Vector2d d = plan.path[i] - plan.path[i - 1];
      for (double f = 0.0; f <= 1.0; f += 0.01) {
        const Eigen::Vector2d p = plan.path[i - 1] + f * d;
        EXPECT_GE(planner.Clearance({p.x(), p.y(), std::atan2(d.y(), d.x())}), parameters.min_clearance - 1e-9)
            << "seed " << seed << " at " << p.transpose();
      }
      tightest = std::min(tightest, plan.clearance[i - 1]);
    }
    EXPECT_LT(tightest, FollowerParameters{}.exact_below) << "seed " << seed;
    EXPECT_GE(tightest, parameters.min_clearance - 1e-9) << "seed " << seed;
  }
}

// The bush servo on a kinematic base: from 1.5 m off, with measurements of the bush's centre
// every 0.4 s (1 cm noise), it stops with the arm's axis at the standoff, the bush straight ahead.
TEST(BushServo, DrivesTheArmToTheStandoffAndConfirmsStandingStill) {
  BushServoParameters parameters;
  const Eigen::Vector2d arm_axis(0.23, 0.0), bush(3.0, 1.0);
  BushServo servo(parameters, arm_axis);
  Pose2 pose{1.6, 0.2, 0.3};                              // the bush about 20 deg to the left
  servo.Expect(bush + Eigen::Vector2d(0.1, -0.1), 0.35);  // the map's belief, 14 cm off
  servo.Start(0.0);
  std::uint64_t state = 12345;
  const auto noise = [&state]() {  // deterministic, roughly uniform in [-1, 1]
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / static_cast<double>(1ULL << 52) - 1.0;
  };
  double t = 0.0;
  for (; t < 60.0 && servo.mode() != BushServo::Mode::kDone; t += 0.05) {
    if (std::fmod(t + 1e-9, 0.4) < 0.05) {
      const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
      const Eigen::Vector2d d = bush - Eigen::Vector2d(pose.x, pose.y);
      const Eigen::Vector2d in_base(c * d.x() + s * d.y() + 0.01 * noise(), -s * d.x() + c * d.y() + 0.01 * noise());
      servo.AddMeasurement(t, pose, in_base);
    }
    const messages::BaseVelocityCommand command = servo.Update(t, pose);
    pose.x += command.linear * std::cos(pose.yaw) * 0.05;
    pose.y += command.linear * std::sin(pose.yaw) * 0.05;
    pose.yaw += command.angular * 0.05;
  }
  ASSERT_EQ(servo.mode(), BushServo::Mode::kDone) << "not done after " << t << " s";
  const Eigen::Vector2d arm = Eigen::Vector2d(pose.x, pose.y) + Eigen::Rotation2Dd(pose.yaw) * arm_axis;
  const Eigen::Vector2d to_bush = Eigen::Rotation2Dd(-pose.yaw) * (bush - arm);
  EXPECT_NEAR(to_bush.norm(), 0.35 + parameters.surface_gap, 0.01);
  EXPECT_NEAR(std::atan2(to_bush.y(), to_bush.x()), 0.0, 1.0 * M_PI / 180.0);
}

TEST(BushServo, GivesUpWhenTheBushIsNotSeen) {
  BushServo servo(BushServoParameters{}, {0.23, 0.0});
  servo.Expect({2.0, 0.0}, 0.3);
  servo.Start(0.0);
  for (int k = 0; k <= BushServoParameters{}.max_lost_frames; ++k) servo.AddMiss(0.4 * k);
  EXPECT_EQ(servo.mode(), BushServo::Mode::kFailed);
  EXPECT_NE(servo.failure().find("bush lost"), std::string::npos) << servo.failure();
  // A measurement far from the belief is not the bush.
  BushServo other(BushServoParameters{}, {0.23, 0.0});
  other.Expect({2.0, 0.0}, 0.3);
  EXPECT_FALSE(other.AddMeasurement(0.0, Pose2{}, {2.0, 1.0}));
  EXPECT_FALSE(other.tracking());
}

}  // namespace
}  // namespace trimbot::stack
