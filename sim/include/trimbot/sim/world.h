#pragma once
// A loaded MuJoCo world: model, data and the indices the simulator needs (actuators, joints,
// cameras, sensors, and which garden object each geom belongs to).
#include <mujoco/mujoco.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "trimbot/messages/commands.h"
#include "trimbot/sim/world_builder.h"

namespace trimbot::sim {

class World {
 public:
  // Loads the MJCF written by ComposeWorld. Throws InputError naming the file on failure.
  explicit World(const WorldSpec& spec);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  mjModel* model() const { return model_; }
  mjData* data() const { return data_; }

  struct JointIndex {
    int joint = -1;
    int qpos = -1;
    int dof = -1;
    int actuator = -1;
  };
  const JointIndex& left_wheel() const { return left_wheel_; }
  const JointIndex& right_wheel() const { return right_wheel_; }
  const std::array<JointIndex, messages::kArmJoints>& arm() const { return arm_; }
  const JointIndex& cutter() const { return cutter_; }
  int base_body() const { return base_body_; }
  int imu_site() const { return imu_site_; }
  int accelerometer_adr() const { return accelerometer_adr_; }
  int gyro_adr() const { return gyro_adr_; }
  int left_wheel_geom() const { return left_wheel_geom_; }
  int right_wheel_geom() const { return right_wheel_geom_; }
  // MuJoCo camera id of rig camera i.
  int camera_id(int rig_index) const { return camera_ids_.at(static_cast<size_t>(rig_index)); }
  // Label of a geom, or nullptr for geoms without one.
  const GeomLabel* label(int geom_id) const;
  // Geoms of the robot's own collision set (for contact queries).
  bool is_robot_geom(int geom_id) const;

 private:
  JointIndex FindJoint(const std::string& name, const std::string& actuator) const;

  std::string path_;
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  JointIndex left_wheel_, right_wheel_, cutter_;
  std::array<JointIndex, messages::kArmJoints> arm_{};
  int base_body_ = -1;
  int imu_site_ = -1;
  int accelerometer_adr_ = -1;
  int gyro_adr_ = -1;
  int left_wheel_geom_ = -1;
  int right_wheel_geom_ = -1;
  std::vector<int> camera_ids_;
  std::vector<GeomLabel> geom_labels_;  // indexed by geom id
  std::vector<bool> has_label_;
};

}  // namespace trimbot::sim
