"""A fake robot with every sensor stream, for ``test_ros2_robot.py``: plain rclpy only.

It plays the obstacle course rover's drivers: a ``sensor_msgs/msg/LaserScan`` (the lidar's
31 declared beams), ``NavSatFix``, the compass's ``Imu``, a wheel odometry's
``nav_msgs/msg/Odometry`` and an IMU's ``Imu``, each in its documented frame with values of
its own, with the sensor-data QoS; it listens to the data topics the boundary publishes and
to the ``JointState`` wheel commands, until every data topic has carried a value and the
pilot has commanded the wheels. Usage: ``streams_node.py OUT.json``.
"""

import json
import math
import sys
import time

import rclpy
from nav_msgs.msg import Odometry
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from sensor_msgs.msg import Imu, JointState, LaserScan, NavSatFix, NavSatStatus
from std_msgs.msg import Float64, Float64MultiArray

LAT0, LON0 = 43.5616, 1.4683  # the package's documented origin
A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)
S2 = math.sin(math.radians(LAT0)) ** 2
M = A * (1 - E2) / (1 - E2 * S2) ** 1.5
N = A / math.sqrt(1 - E2 * S2) * math.cos(math.radians(LAT0))
WAIT_S = 120
BEAMS, LO, HI = 31, -1.5708, 1.5708  # the world's Scanner
RANGES = [1.0 + 0.25 * i for i in range(BEAMS)]
SCALARS = [
    "/Gps/gpsPosX",
    "/Gps/gpsPosY",
    "/Heading/compassHeading",
    "/Odometry/odomX",
    "/Odometry/odomY",
    "/Odometry/odomHeading",
    "/Imu/gyroZ",
    "/Imu/accelX",
    "/Imu/accelY",
]


def quaternion(msg, yaw):
    msg.z, msg.w = math.sin(yaw / 2), math.cos(yaw / 2)


def main():
    rclpy.init()
    node = rclpy.create_node("test_rover")
    qos = qos_profile_sensor_data
    scan_pub = node.create_publisher(LaserScan, "/Rover/Scanner/scan", qos)
    fix_pub = node.create_publisher(NavSatFix, "/Rover/Gps/fix", qos)
    heading_pub = node.create_publisher(Imu, "/Rover/Heading/heading", qos)
    odom_pub = node.create_publisher(Odometry, "/Rover/Odometry/odom", qos)
    imu_pub = node.create_publisher(Imu, "/Rover/Imu/imu", qos)
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    last = {}
    for topic in SCALARS:
        node.create_subscription(
            Float64, topic, lambda m, topic=topic: last.__setitem__(topic, m.data), reliable
        )
    node.create_subscription(
        Float64MultiArray,
        "/Scanner/ranges",
        lambda m: last.__setitem__("/Scanner/ranges", list(m.data)),
        reliable,
    )
    commands = []
    node.create_subscription(
        JointState, "/Rover/wheel_cmd", lambda m: commands.append(list(m.effort)), reliable
    )

    scan = LaserScan()
    scan.header.frame_id = "Rover/base_link"
    scan.angle_min, scan.angle_max = LO, HI
    scan.angle_increment = (HI - LO) / (BEAMS - 1)
    scan.range_min, scan.range_max = 0.1, 20.0
    scan.ranges = RANGES
    fix = NavSatFix()
    fix.header.frame_id = "Rover/base_link"
    fix.status.status, fix.status.service = NavSatStatus.STATUS_FIX, NavSatStatus.SERVICE_GPS
    fix.latitude, fix.longitude = LAT0 + math.degrees(-1.5 / M), LON0 + math.degrees(4.0 / N)
    heading = Imu()
    heading.header.frame_id = "Rover/base_link"
    quaternion(heading.orientation, 0.7)
    odom = Odometry()
    odom.header.frame_id, odom.child_frame_id = "Rover/odom", "Rover/base_link"
    odom.pose.pose.position.x, odom.pose.pose.position.y = 3.0, -2.0
    quaternion(odom.pose.pose.orientation, -0.4)
    imu = Imu()
    imu.header.frame_id = "Rover/base_link"
    quaternion(imu.orientation, 0.0)
    imu.angular_velocity.z = 0.25
    imu.linear_acceleration.x, imu.linear_acceleration.y, imu.linear_acceleration.z = 0.5, -0.1, 9.8

    deadline = time.monotonic() + WAIT_S
    while time.monotonic() < deadline:
        for pub, msg in (
            (scan_pub, scan),
            (fix_pub, fix),
            (heading_pub, heading),
            (odom_pub, odom),
            (imu_pub, imu),
        ):
            pub.publish(msg)
        end = time.monotonic() + 0.05
        while time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=max(0.0, end - time.monotonic()))
        if len(last) == len(SCALARS) + 1 and len(commands) >= 3:
            break
    with open(sys.argv[1], "w") as f:
        json.dump({"last": last, "commands": commands, "ranges": RANGES}, f)
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
