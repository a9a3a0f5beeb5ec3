"""A fake robot for ``test_ros2_robot.py``: plain rclpy and the standard messages only.

It plays a robot's drivers for the exported package's ``amsa-phys ros2 robot``: for each
scripted scene (leader position, follower position and heading) it publishes
``sensor_msgs/msg/NavSatFix`` for both GPS receivers and the compass's ``sensor_msgs/msg/Imu``
orientation, with the sensor-data QoS (best effort) a real driver uses, until the wheel
commands (``sensor_msgs/msg/JointState`` on ``/Follower/wheel_cmd``) have settled; then it
sends hostile messages (a NaN latitude, another frame, an orientation the message says it
does not provide, a String on a fix topic) and records what reached the data topics and what
the boundary said on ``/rosout``. Usage: ``robot_node.py SCENES.json OUT.json``.
"""

import json
import math
import sys
import time

import rclpy
from rcl_interfaces.msg import Log
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from sensor_msgs.msg import Imu, JointState, NavSatFix, NavSatStatus
from std_msgs.msg import Float64, String

LAT0, LON0 = 43.5616, 1.4683  # the package's documented origin
A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)
S2 = math.sin(math.radians(LAT0)) ** 2
M = A * (1 - E2) / (1 - E2 * S2) ** 1.5  # metres per radian of latitude
N = A / math.sqrt(1 - E2 * S2) * math.cos(math.radians(LAT0))  # ... of longitude
WAIT_S = 120  # wall seconds a stage may take on a loaded machine before the robot gives up
SETTLED = 3  # equal commands in a row
AT_LEAST = 8  # commands since the scene began, before it may count as settled


def fix(x, y, frame, lat=None):
    msg = NavSatFix()
    msg.header.frame_id = frame
    msg.status.status, msg.status.service = NavSatStatus.STATUS_FIX, NavSatStatus.SERVICE_GPS
    msg.latitude = LAT0 + math.degrees(y / M) if lat is None else lat
    msg.longitude = LON0 + math.degrees(x / N)
    msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_UNKNOWN
    return msg


def heading(yaw, provided=True):
    msg = Imu()
    msg.header.frame_id = "Follower/base_link"
    msg.orientation.z, msg.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    if not provided:
        msg.orientation_covariance[0] = -1.0
    return msg


def main():
    with open(sys.argv[1]) as f:
        scenes = json.load(f)
    rclpy.init()
    node = rclpy.create_node("test_robot")
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    lead = node.create_publisher(NavSatFix, "/Leader/LeaderGPS/fix", qos_profile_sensor_data)
    own = node.create_publisher(NavSatFix, "/Follower/FollowerGPS/fix", qos_profile_sensor_data)
    compass = node.create_publisher(
        Imu, "/Follower/FollowerCompass/heading", qos_profile_sensor_data
    )
    commands = []
    node.create_subscription(
        JointState,
        "/Follower/wheel_cmd",
        lambda m: commands.append(
            [list(m.name), list(m.effort), m.header.frame_id, m.header.stamp.sec]
        ),
        reliable,
    )
    seen = {
        "/LeaderGPS/gpsPosX": [],
        "/LeaderGPS/gpsPosY": [],
        "/FollowerCompass/compassHeading": [],
    }
    for topic, values in seen.items():
        node.create_subscription(
            Float64, topic, lambda m, values=values: values.append(m.data), reliable
        )
    said = []

    def on_log(m):
        if m.name == "amsa_boundary":
            said.append([m.name, m.msg])

    node.create_subscription(
        Log, "/rosout", on_log, QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    )

    def publish(scene):
        lx, ly, fx, fy, fh = scene
        lead.publish(fix(lx, ly, "Leader/base_link"))
        own.publish(fix(fx, fy, "Follower/base_link"))
        compass.publish(heading(fh))

    def spin_for(seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=max(0.0, end - time.monotonic()))

    out = {"scenes": [], "commands": commands, "seen": seen, "said": said}
    for scene in scenes:
        start = len(commands)
        deadline = time.monotonic() + WAIT_S
        while True:
            publish(scene)  # a driver's own rate: 20 Hz
            spin_for(0.05)
            new = [c[1] for c in commands[start:]]
            if len(new) >= AT_LEAST and all(c == new[-1] for c in new[-SETTLED:]):
                out["scenes"].append({"scene": scene, "effort": new[-1], "n": len(new)})
                break
            if time.monotonic() > deadline:
                out["scenes"].append({"scene": scene, "effort": None, "n": len(new)})
                break
    # hostile drivers: each message has a value that must never reach a data topic
    other = rclpy.Context()  # a participant of its own: one may not hold two types of a topic
    rclpy.init(context=other)
    hostile = rclpy.create_node("hostile_driver", context=other)
    string = hostile.create_publisher(String, "/Leader/LeaderGPS/fix", reliable)
    wanted = [
        "latitude is nan",
        "frame_id 'gps_link', expected 'Leader/base_link'",
        "orientation not provided (orientation_covariance[0] = -1)",
        "publishes std_msgs/msg/String on /Leader/LeaderGPS/fix",
    ]
    deadline = time.monotonic() + WAIT_S
    while time.monotonic() < deadline:
        lead.publish(fix(0.0, 0.0, "Leader/base_link", lat=math.nan))
        spin_for(0.05)
        lead.publish(fix(1000.0, 1000.0, "gps_link"))
        compass.publish(heading(2.0, provided=False))
        string.publish(String(data="not a fix"))
        spin_for(0.05)
        if all(any(w in m for _, m in said) for w in wanted):
            break
    # and the boundary still works: the last scene's command again
    scene = scenes[-1]
    start = len(commands)
    deadline = time.monotonic() + WAIT_S
    while len(commands) - start < AT_LEAST and time.monotonic() < deadline:
        publish(scene)
        spin_for(0.05)
    out["after"] = [c[1] for c in commands[start:]]
    with open(sys.argv[2], "w") as f:
        json.dump(out, f)
    hostile.destroy_node()
    rclpy.try_shutdown(context=other)
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
