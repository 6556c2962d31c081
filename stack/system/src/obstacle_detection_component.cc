#include "obstacle_detection_component.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "trimbot/common/pose2.h"
#include "trimbot/perception/obstacle_points.h"

namespace trimbot::stack {

ObstacleDetectionComponent::ObstacleDetectionComponent(const StackParameters& parameters, const robot::CameraRig& rig)
    : parameters_(parameters) {
  if (parameters.obstacles.enabled) {
    perception::StereoOptions stereo;
    stereo.stride = parameters.obstacles.stride;
    stereo_ = std::make_unique<perception::RingStereo>(rig, stereo);
  }
}

void ObstacleDetectionComponent::SetMap(const OccupancyGrid& map) {
  if (stereo_) layer_ = std::make_unique<ObstacleLayer>(map, parameters_.obstacles.layer);
}

std::vector<int> ObstacleDetectionComponent::PairsAhead(double linear_command) const {
  // Backing off looks backwards; driving, turning or standing looks forwards.
  const double travel = linear_command < 0.0 ? M_PI : 0.0;
  std::vector<int> pairs;
  const auto& rectifiers = stereo_->rectifiers();
  for (std::size_t i = 0; i < rectifiers.size(); ++i) {
    const Eigen::Vector3d axis = rectifiers[i].T_base_rectified_left().linear().col(2);
    const double bearing = std::atan2(axis.y(), axis.x());
    if (std::abs(WrapAngle(bearing - travel)) <= parameters_.obstacles.max_bearing) {
      pairs.push_back(static_cast<int>(i));
    }
  }
  return pairs;
}

bool ObstacleDetectionComponent::Due(double stamp, const StackState& /*state*/) const {
  return stereo_ && layer_ && stamp + 1e-9 >= next_frame_;
}

messages::RingRequest ObstacleDetectionComponent::Request(const StackState& state) const {
  // Empty when no pair faces the direction of travel (backing off, none facing backwards): the
  // component is due all the same, and a frame delivered for another one restarts its period.
  std::vector<robot::StereoPair> ahead;
  for (int pair : PairsAhead(state.last_linear_command)) {
    ahead.push_back(stereo_->rectifiers()[static_cast<std::size_t>(pair)].pair());
  }
  return PairsRequest(ahead);
}

void ObstacleDetectionComponent::Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) {
  ScopedTimer timer(&telemetry->timings.obstacles);
  next_frame_ = frame.stamp + 1.0 / parameters_.obstacles.rate_hz;
  const Eigen::Isometry3d T_map_base = ToIsometry(state->ekf.Estimate().pose);
  perception::ObstaclePointOptions options = parameters_.obstacles.points;
  // The robot's own body (base, ring, arm at rest) is the base's outline with a margin.
  const double margin = 0.05;
  options.robot_min = state->outline.min() - Eigen::Vector2d::Constant(margin);
  options.robot_max = state->outline.max() + Eigen::Vector2d::Constant(margin);
  ObstacleObservation observation;
  observation.stamp = frame.stamp;
  observation.min_obstacle_height = options.min_height;
  for (int pair : PairsAhead(state->last_linear_command)) {
    const perception::StereoRectifier& rectifier = stereo_->rectifiers()[static_cast<std::size_t>(pair)];
    if (!PairDelivered(frame, rectifier.pair())) continue;
    const perception::RingStereo::PairResult result = stereo_->ComputePair(frame, pair);
    const perception::ObstaclePoints points =
        perception::FindObstaclePoints(result.cloud, rectifier.T_base_rectified_left().translation(), options);
    ObstacleView view;
    view.sensor = (T_map_base * points.sensor).head<2>();
    view.sensor_height = points.ground.Distance(points.sensor);
    view.obstacles.reserve(points.obstacles.size());
    for (const Eigen::Vector3d& p : points.obstacles) view.obstacles.push_back((T_map_base * p).head<2>());
    view.ground.reserve(points.ground_points.size());
    for (const Eigen::Vector3d& p : points.ground_points) view.ground.push_back((T_map_base * p).head<2>());
    observation.views.push_back(std::move(view));
    ++telemetry->timings.obstacle_pairs;
  }
  if (observation.views.empty()) return;
  layer_->Integrate(observation);
  ++telemetry->obstacles.frames;
  telemetry->obstacles.occupied_cells = layer_->OccupiedCells();
  if (state->navigator) {
    state->navigator->SetCostmap(layer_->MergedWith(*state->map));
    ++telemetry->obstacles.costmap_updates;
  }
}

}  // namespace trimbot::stack
