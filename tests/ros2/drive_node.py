"""A fake robot in closed loop, for ``test_ros2_robot.py``: plain rclpy only.

Its own differential-drive kinematics (5.5 m/s at 100 % effort, a 0.5 m track) obey the
``sensor_msgs/msg/JointState`` wheel commands; its own leader drives straight at 0.2 m/s,
starting 25 m ahead. On each 0.05 s of the boundary's ``/clock`` it moves both and publishes
both GPS fixes and the compass. After ``END`` simulated seconds it writes the distances.
Usage: ``drive_node.py END OUT.json``.
"""

import json
import math
import sys

import rclpy
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState, NavSatFix, NavSatStatus

LAT0, LON0 = 43.5616, 1.4683
A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)
S2 = math.sin(math.radians(LAT0)) ** 2
M = A * (1 - E2) / (1 - E2 * S2) ** 1.5
N = A / math.sqrt(1 - E2 * S2) * math.cos(math.radians(LAT0))
DT = 0.05


def fix(x, y, frame, stamp):
    msg = NavSatFix()
    msg.header.stamp, msg.header.frame_id = stamp, frame
    msg.status.status, msg.status.service = NavSatStatus.STATUS_FIX, NavSatStatus.SERVICE_GPS
    msg.latitude = LAT0 + math.degrees(y / M)
    msg.longitude = LON0 + math.degrees(x / N)
    return msg


def main():
    end = float(sys.argv[1])
    rclpy.init()
    node = rclpy.create_node("test_drive")
    qos = qos_profile_sensor_data
    lead = node.create_publisher(NavSatFix, "/Leader/LeaderGPS/fix", qos)
    own = node.create_publisher(NavSatFix, "/Follower/FollowerGPS/fix", qos)
    compass = node.create_publisher(Imu, "/Follower/FollowerCompass/heading", qos)
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    effort = [0.0, 0.0]
    count = [0]

    def on_cmd(m):
        effort[:] = [
            m.effort[m.name.index("left_wheel_joint")],
            m.effort[m.name.index("right_wheel_joint")],
        ]
        count[0] += 1

    node.create_subscription(JointState, "/Follower/wheel_cmd", on_cmd, reliable)
    clock = [None]
    node.create_subscription(Clock, "/clock", lambda m: clock.__setitem__(0, m.clock), reliable)
    xl, yl, vl = 25.0, 0.0, 0.2
    x = y = th = 0.0
    t_last = None
    log = []
    while rclpy.ok():
        rclpy.spin_once(node, timeout_sec=1.0)
        if clock[0] is None:
            continue
        t = clock[0].sec + clock[0].nanosec / 1e9
        if t_last is None:
            t_last, t0 = t, t
        if t - t_last < DT:
            continue
        dt, t_last = t - t_last, t
        v_l, v_r = (5.5 * max(-100.0, min(100.0, e)) / 100 for e in effort)
        v, w = (v_l + v_r) / 2, (v_r - v_l) / 0.5
        x += v * math.cos(th) * dt
        y += v * math.sin(th) * dt
        th += w * dt
        xl += vl * dt
        lead.publish(fix(xl, yl, "Leader/base_link", clock[0]))
        own.publish(fix(x, y, "Follower/base_link", clock[0]))
        imu = Imu()
        imu.header.stamp, imu.header.frame_id = clock[0], "Follower/base_link"
        imu.orientation.z, imu.orientation.w = math.sin(th / 2), math.cos(th / 2)
        compass.publish(imu)
        log.append([t - t0, math.hypot(xl - x, yl - y), x, y])
        if t - t0 >= end:
            break
    with open(sys.argv[2], "w") as f:
        json.dump({"log": log, "commands": count[0]}, f)
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
