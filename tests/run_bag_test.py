#!/usr/bin/python3
"""run.bag of a trial read back with Debian's python3-rosbag (issue 32): the topics and their
message types; message counts at the rates the robot's sensors and the bag run at; the REP-105 /tf
chain map -> odom -> base_link -> cam0_optical_frame complete, and map -> base_link through it equal
to the EKF's pose; the ground-truth poses equal to the trial's ground_truth.tum.

Usage: run_bag_test.py TRIAL_DIR ROBOT_PARAMETERS_YAML (a trial with visual localization)."""
import json
import math
import sys

import rosbag
import yaml

from script_checks import check, finish

trial_dir, robot_parameters = sys.argv[1], sys.argv[2]

result = json.load(open(trial_dir + "/result.json"))
parameters = yaml.safe_load(open(robot_parameters))
duration = result["simulated_seconds"]
bag = rosbag.Bag(trial_dir + "/run.bag")
topics = bag.get_type_and_topic_info().topics
expected_types = {
    "/tf": "tf2_msgs/TFMessage",
    "/tf_static": "tf2_msgs/TFMessage",
    "/ground_truth/pose": "geometry_msgs/PoseStamped",
    "/ekf/pose": "geometry_msgs/PoseWithCovarianceStamped",
    "/wheel_odometry": "nav_msgs/Odometry",
    "/imu": "sensor_msgs/Imu",
    "/joint_states": "sensor_msgs/JointState",
    "/visual_localization/fix": "geometry_msgs/PoseWithCovarianceStamped",
    "/cmd_vel": "geometry_msgs/Twist",
    "/cam0/image/compressed": "sensor_msgs/CompressedImage",
    "/events": "std_msgs/String",
    "/costmap": "nav_msgs/OccupancyGrid",
}
for topic, msg_type in expected_types.items():
    check(topic in topics and topics[topic].msg_type == msg_type, f"{topic} holds {msg_type}")
count = {topic: info.message_count for topic, info in topics.items()}


def near_rate(topic, rate_hz):
    expected = rate_hz * duration
    check(abs(count.get(topic, 0) - expected) <= 0.01 * expected + 2,
          f"{topic}: {count.get(topic, 0)} messages, {expected:.0f} at {rate_hz} Hz over {duration:.2f} s")


near_rate("/imu", parameters["imu"]["rate_hz"])
for topic in ("/ground_truth/pose", "/ekf/pose", "/wheel_odometry"):
    near_rate(topic, 50.0)  # the bag's pose rate
frames = count.get("/cam0/image/compressed", 0)
check(0 < frames <= parameters["cameras"]["rate_hz"] * duration + 1,
      f"/cam0/image/compressed: {frames} frames, at most the ring's {parameters['cameras']['rate_hz']} Hz")
accepted = result["fixes_accepted"] + result["fixes_rejected"]
check(count.get("/visual_localization/fix", 0) == accepted,
      f"/visual_localization/fix: {count.get('/visual_localization/fix', 0)} fixes, the trial counted {accepted}")

# The /tf chain, and map -> base_link through it against the EKF's pose at the same stamps.
static = {}
for _, message, _ in bag.read_messages(topics=["/tf_static"]):
    for t in message.transforms:
        static[(t.header.frame_id, t.child_frame_id)] = t
check(("base_link", "cam0_optical_frame") in static, "/tf_static: base_link -> cam0_optical_frame")
check(("base_link", "imu_link") in static, "/tf_static: base_link -> imu_link")
near_rate("/costmap", 1.0)
grid = next(bag.read_messages(topics=["/costmap"]))[1]
check(grid.info.width * grid.info.height == len(grid.data) and 100 in grid.data and 0 in grid.data,
      f"/costmap: a {grid.info.width} x {grid.info.height} grid at {grid.info.resolution} m with obstacles and free cells")

# The arm: base_link -> arm_link_base (static) -> arm_link_1 ... arm_link_6 (/tf at each joint
# state) -> arm_end_effector (static).
arm_links = set()
for _, message, _ in bag.read_messages(topics=["/tf"]):
    for t in message.transforms:
        if t.child_frame_id.startswith("arm_link_"):
            arm_links.add((t.header.frame_id, t.child_frame_id))
chain = [("base_link", "arm_link_base")] + [
    (("arm_link_base" if k == 1 else f"arm_link_{k - 1}"), f"arm_link_{k}") for k in range(1, 7)] + [
    ("arm_link_6", "arm_end_effector")]
found = [link in arm_links or link in static for link in chain]
check(all(found), "the arm's chain base_link -> arm_link_base -> arm_link_1..6 -> arm_end_effector: " +
      ", ".join(f"{a}->{b}" for (a, b), ok in zip(chain, found) if not ok) if not all(found) else
      "the arm's chain base_link -> arm_link_base -> arm_link_1..6 -> arm_end_effector is complete")


def planar(translation, rotation):
    yaw = 2.0 * math.atan2(rotation.z, rotation.w)
    return translation.x, translation.y, yaw


def compose(a, b):
    x, y, yaw = a
    return (x + math.cos(yaw) * b[0] - math.sin(yaw) * b[1], y + math.sin(yaw) * b[0] + math.cos(yaw) * b[1],
            yaw + b[2])


ekf = {m.header.stamp.to_nsec(): m for _, m, _ in bag.read_messages(topics=["/ekf/pose"])}
worst, chains, compared = 0.0, 0, 0
for _, message, _ in bag.read_messages(topics=["/tf"]):
    frames_of = {(t.header.frame_id, t.child_frame_id): t for t in message.transforms}
    if ("map", "odom") not in frames_of or ("odom", "base_link") not in frames_of:
        continue
    chains += 1
    m_o, o_b = frames_of[("map", "odom")], frames_of[("odom", "base_link")]
    x, y, yaw = compose(planar(m_o.transform.translation, m_o.transform.rotation),
                        planar(o_b.transform.translation, o_b.transform.rotation))
    e = ekf.get(m_o.header.stamp.to_nsec())
    if e is None:
        continue
    compared += 1
    p = e.pose.pose
    ex, ey, eyaw = planar(p.position, p.orientation)
    worst = max(worst, math.hypot(x - ex, y - ey), abs(math.remainder(yaw - eyaw, 2 * math.pi)))
check(chains == count.get("/tf", -1) - count.get("/joint_states", 0) and abs(chains - 50.0 * duration) <= 0.01 * 50.0 * duration + 2,
      f"/tf: map -> odom -> base_link at 50 Hz, in all {chains} messages but the arm's")
check(compared == chains and worst < 1e-6,
      f"map -> odom -> base_link is the EKF's pose at all {compared} stamps (worst {worst:.2e})")

# Ground truth: every pose of ground_truth.tum in the bag, at its stamp.
truth = {round(m.header.stamp.to_sec(), 6): m.pose for _, m, _ in bag.read_messages(topics=["/ground_truth/pose"])}
lines = [l.split() for l in open(trial_dir + "/ground_truth.tum") if l.strip() and not l.startswith("#")]
worst, worst_z, missing = 0.0, 0.0, 0
for fields in lines:
    t, x, y, z, qx, qy, qz, qw = map(float, fields)
    pose = truth.get(round(t, 6))
    if pose is None:
        missing += 1
        continue
    # ground_truth.tum is the planar pose the evaluation uses (z, roll and pitch 0); the bag holds
    # the body's full pose, so x, y and yaw are compared, and z within the wheels' sinkage.
    yaw = 2.0 * math.atan2(qz, qw)
    _, _, bag_yaw = planar(pose.position, pose.orientation)
    worst = max(worst, abs(pose.position.x - x), abs(pose.position.y - y),
                abs(math.remainder(bag_yaw - yaw, 2 * math.pi)))
    worst_z = max(worst_z, abs(pose.position.z - z))
check(missing == 0, f"ground_truth.tum: {len(lines) - missing} of {len(lines)} stamps in /ground_truth/pose")
check(worst < 2e-6, f"/ground_truth/pose: x, y, yaw equal ground_truth.tum's (worst {worst:.1e}, the file's 6 decimals)")
check(worst_z < 0.005, f"/ground_truth/pose: z within 5 mm of the ground plane (worst {worst_z:.1e} m)")

image = next(bag.read_messages(topics=["/cam0/image/compressed"]))[1]
check(image.format == "jpeg" and bytes(image.data[:2]) == b"\xff\xd8", "cam0 images are JPEG")
finish()
