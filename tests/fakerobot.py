"""A robot of a test's own, as a plain rospy script (no amsa-phys code): the parts every such
robot shares, so ``sim:=false`` tests (tests/ros/test_ros_robot.py, test_ros_arrays.py) write
only what their robot does.

:func:`script` joins them: the imports, the WGS 84 plane at the package's documented origin
(43.5616 N, 1.4683 E) with ``fix()`` to publish a ``NavSatFix`` of a point on it, the wheel
commands (``sensor_msgs/JointState`` efforts, % of full power) on the test's topic, then a
20 Hz loop on simulated time that integrates a differential drive (5.5 m/s at 100 %, a
0.5 m track) from ``x, y, th`` and runs the robot's own ``body`` (sensors, the end test).
"""

from __future__ import annotations

import textwrap

_HEAD = """#!/usr/bin/python3
import json, math, sys
import rospy
from sensor_msgs.msg import Imu, JointState, NavSatFix, NavSatStatus
{imports}
LAT0, LON0 = 43.5616, 1.4683
A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)
S2 = math.sin(math.radians(LAT0)) ** 2
M = A * (1 - E2) / (1 - E2 * S2) ** 1.5              # metres per radian of latitude
N = A / math.sqrt(1 - E2 * S2) * math.cos(math.radians(LAT0))  # ... of longitude

def fix(pub, x, y, stamp, frame, covariance=True):
    msg = NavSatFix()
    msg.header.stamp, msg.header.frame_id = stamp, frame
    msg.status.status, msg.status.service = NavSatStatus.STATUS_FIX, NavSatStatus.SERVICE_GPS
    msg.latitude = LAT0 + math.degrees(y / M)
    msg.longitude = LON0 + math.degrees(x / N)
    if covariance:
        msg.position_covariance = [1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 0]
        msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN
    pub.publish(msg)

def heading(pub, th, stamp, frame):
    imu = Imu()
    imu.header.stamp, imu.header.frame_id = stamp, frame
    imu.orientation.z, imu.orientation.w = math.sin(th / 2), math.cos(th / 2)
    pub.publish(imu)

rospy.init_node("test_robot")
effort = [0.0, 0.0]
commands = [0]
def on_cmd(msg):
    effort[:] = [msg.effort[msg.name.index("left_wheel_joint")],
                 msg.effort[msg.name.index("right_wheel_joint")]]
    commands[0] += 1
rospy.Subscriber({wheel_cmd!r}, JointState, on_cmd)
{setup}
END, DT = float(sys.argv[1]), 0.05
rate = rospy.Rate(1 / DT)   # simulated time: the boundary node's /clock
t0 = None
while not rospy.is_shutdown():
    try:
        rate.sleep()
    except rospy.ROSInterruptException:
        break
    now = rospy.Time.now()
    t = now.to_sec()
    t0 = t if t0 is None else t0
    vL, vR = (5.5 * max(-100.0, min(100.0, e)) / 100 for e in effort)
    v, w = (vL + vR) / 2, (vR - vL) / 0.5
    x += v * math.cos(th) * DT
    y += v * math.sin(th) * DT
    th += w * DT
{body}
with open(sys.argv[2], "w") as f:
    json.dump({result}, f)
"""


def script(wheel_cmd: str, imports: str, setup: str, body: str, result: str) -> str:
    """The robot's script: ``setup`` runs once (it sets ``x, y, th`` and its publishers),
    ``body`` each loop step after the drive moved (indented here; ``break`` ends the run),
    ``result`` is the expression written as JSON to ``argv[2]``; ``argv[1]`` is the run's
    length in simulated seconds."""
    return _HEAD.format(
        imports=textwrap.dedent(imports).strip(),
        wheel_cmd=wheel_cmd,
        setup=textwrap.dedent(setup).strip(),
        body=textwrap.indent(textwrap.dedent(body).strip(), "    "),
        result=result,
    )
