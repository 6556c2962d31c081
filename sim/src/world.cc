#include "trimbot/sim/world.h"

#include "trimbot/common/input_error.h"
#include "trimbot/robot/robot_description.h"

namespace trimbot::sim {

using robot::RobotFrames;

World::World(const WorldSpec& spec) : path_(spec.mjcf_path) {
  char error[1024] = "";
  model_ = mj_loadXML(path_.c_str(), nullptr, error, sizeof(error));
  if (model_ == nullptr) throw InputError(path_, std::string("MuJoCo could not load the world: ") + error);
  data_ = mj_makeData(model_);

  left_wheel_ = FindJoint(RobotFrames::kLeftWheelJoint, std::string(RobotFrames::kLeftWheelJoint) + "_motor");
  right_wheel_ = FindJoint(RobotFrames::kRightWheelJoint, std::string(RobotFrames::kRightWheelJoint) + "_motor");
  cutter_ = FindJoint(RobotFrames::kCutterJoint, "cutter_motor");
  for (int i = 0; i < messages::kArmJoints; ++i) {
    arm_[static_cast<size_t>(i)] = FindJoint(RobotFrames::ArmJoint(i), RobotFrames::ArmJoint(i) + "_servo");
  }
  base_body_ = mj_name2id(model_, mjOBJ_BODY, RobotFrames::kBase);
  imu_site_ = mj_name2id(model_, mjOBJ_SITE, RobotFrames::kImu);
  const int accelerometer = mj_name2id(model_, mjOBJ_SENSOR, "imu_accelerometer");
  const int gyro = mj_name2id(model_, mjOBJ_SENSOR, "imu_gyro");
  left_wheel_geom_ = mj_name2id(model_, mjOBJ_GEOM, "left_wheel_link/collision0");
  right_wheel_geom_ = mj_name2id(model_, mjOBJ_GEOM, "right_wheel_link/collision0");
  if (base_body_ < 0 || imu_site_ < 0 || accelerometer < 0 || gyro < 0 || left_wheel_geom_ < 0 ||
      right_wheel_geom_ < 0) {
    throw InputError(path_, "world lacks the robot's base body, IMU site, IMU sensors or wheel geoms");
  }
  accelerometer_adr_ = model_->sensor_adr[accelerometer];
  gyro_adr_ = model_->sensor_adr[gyro];
  for (const auto& name : spec.camera_names) {
    const int id = mj_name2id(model_, mjOBJ_CAMERA, name.c_str());
    if (id < 0) throw InputError(path_, "world lacks camera '" + name + "'");
    camera_ids_.push_back(id);
  }
  geom_labels_.resize(static_cast<size_t>(model_->ngeom));
  has_label_.assign(static_cast<size_t>(model_->ngeom), false);
  for (const auto& label : spec.labels) {
    const int id = mj_name2id(model_, mjOBJ_GEOM, label.geom_name.c_str());
    if (id < 0) throw InputError(path_, "world lacks geom '" + label.geom_name + "'");
    geom_labels_[static_cast<size_t>(id)] = label;
    has_label_[static_cast<size_t>(id)] = true;
  }
  mj_forward(model_, data_);
}

World::~World() {
  mj_deleteData(data_);
  mj_deleteModel(model_);
}

World::JointIndex World::FindJoint(const std::string& name, const std::string& actuator) const {
  JointIndex index;
  index.joint = mj_name2id(model_, mjOBJ_JOINT, name.c_str());
  index.actuator = mj_name2id(model_, mjOBJ_ACTUATOR, actuator.c_str());
  if (index.joint < 0 || index.actuator < 0) {
    throw InputError(path_, "world lacks joint '" + name + "' or its actuator '" + actuator + "'");
  }
  index.qpos = model_->jnt_qposadr[index.joint];
  index.dof = model_->jnt_dofadr[index.joint];
  return index;
}

const GeomLabel* World::label(int geom_id) const {
  if (geom_id < 0 || geom_id >= model_->ngeom || !has_label_[static_cast<size_t>(geom_id)]) return nullptr;
  return &geom_labels_[static_cast<size_t>(geom_id)];
}

bool World::is_robot_geom(int geom_id) const {
  const GeomLabel* l = label(geom_id);
  return l != nullptr && l->object_class == garden::ObjectClass::kRobot;
}

}  // namespace trimbot::sim
