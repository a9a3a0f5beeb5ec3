"""The exported controller drives a robot it has never seen: ``sim:=false`` (issue 26 item 2).

The sensed MDE world (the controller's distance from the two GPS fixes) is exported and
launched with ``sim:=false``: no simulator, no sensor models, only the controller side and
the boundary node. A robot node of this test's own — plain rospy and the standard message
packages, no amsa-phys code — plays the robot: its own differential-drive kinematics,
its own leader driving straight, ``sensor_msgs/NavSatFix`` for both GPS receivers,
``sensor_msgs/Imu`` orientation for the compass, ``nav_msgs/Odometry``; it obeys the
``sensor_msgs/JointState`` wheel commands. It ends the launch after a simulated time and
writes what happened; the follower must have caught up and be within the band behind the
leader. Skipped, with the reason, where ROS or the standard message packages are missing.
"""

from __future__ import annotations

import json
import subprocess
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from fakerobot import script
from ros_launch import build_workspace, ros_missing

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "scenarios" / "paper_fig6_sensed.yaml"
PKG = "mdeChallengeSensed"  # the world's name
REF, BAND = 15.0, 1.5  # the world's distanceRef and the scenario family's quality tolerance


def _missing() -> str | None:
    missing = ros_missing()
    if missing:
        return missing
    probe = subprocess.run(
        ["/usr/bin/python3", "-c", "import sensor_msgs.msg, nav_msgs.msg, tf2_msgs.msg"],
        capture_output=True,
    )
    if probe.returncode != 0:
        return "the ROS standard messages (python3-sensor-msgs, -nav-msgs, -tf2-msgs) are missing"
    return None


pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(_missing() is not None, reason=str(_missing())),
]
launcher = ros_launch.launcher  # the fixture

#: The robot: a leader 15 m ahead driving straight at 0.2 m/s, a follower obeying its wheel
#: efforts (% of full power, 5.5 m/s at 100 %, the rover's free speed) on a 0.5 m track.
#: GPS fixes on the WGS 84 plane at the package's documented origin (43.5616 N, 1.4683 E).
ROBOT = script(
    "/Follower/wheel_cmd",
    "from nav_msgs.msg import Odometry",
    """
    lead_fix = rospy.Publisher("/Leader/LeaderGPS/fix", NavSatFix, queue_size=10)
    own_fix = rospy.Publisher("/Follower/FollowerGPS/fix", NavSatFix, queue_size=10)
    compass = rospy.Publisher("/Follower/FollowerCompass/heading", Imu, queue_size=10)
    odom = rospy.Publisher("/Follower/odom", Odometry, queue_size=10)
    xl, yl, vl = 15.0, 0.0, 0.2
    x = y = th = 0.0
    log = []
    """,
    """
    xl += vl * DT
    fix(lead_fix, xl, yl, now, "Leader/base_link")
    fix(own_fix, x, y, now, "Follower/base_link")
    heading(compass, th, now, "Follower/base_link")
    o = Odometry()
    o.header.stamp, o.header.frame_id, o.child_frame_id = now, "map", "Follower/base_link"
    o.pose.pose.position.x, o.pose.pose.position.y = x, y
    o.pose.pose.orientation.z, o.pose.pose.orientation.w = math.sin(th / 2), math.cos(th / 2)
    o.twist.twist.linear.x, o.twist.twist.angular.z = v, w
    odom.publish(o)
    log.append([t, math.hypot(xl - x, yl - y), x, y])
    if t - t0 >= END:
        break
    """,
    '{"log": log, "commands": commands[0]}',
)


def test_the_exported_controller_drives_a_robot_of_the_tests_own(
    tmp_path_factory: pytest.TempPathFactory, launcher: Callable[..., ros_launch.Launch]
) -> None:
    ws = build_workspace(tmp_path_factory.mktemp("robot_ws"), SCENARIO, PKG)
    pkg = ws / "src" / PKG
    robot = pkg / "test_robot.py"
    robot.write_text(ROBOT)
    robot.chmod(0o755)
    result = ws / "robot.json"
    launch = pkg / "launch" / "robot.launch"
    launch.write_text(
        "<launch>\n"
        f'  <include file="$(find {PKG})/launch/paper_fig6_sensed.launch">\n'
        '    <arg name="sim" value="false"/>\n'
        '    <arg name="speed" value="2"/>\n'
        "  </include>\n"
        f'  <node pkg="{PKG}" type="test_robot.py" name="test_robot" required="true"'
        f' args="40 {result}" output="screen"/>\n'
        "</launch>\n"
    )
    text = launcher(ws, "robot.launch").finish()
    assert result.exists(), text[-3000:]
    data = json.loads(result.read_text())
    log = data["log"]
    assert data["commands"] > 100, text[-3000:]  # obeyed JointState commands all along
    assert "amsa_simulator" not in text.split("NODES")[1].split("auto-starting")[0]
    # the follower moved (the leader drove 8 m on) and holds the band behind it
    assert log[-1][2] > 5.0, log[-1]
    last = [d for t, d, _, _ in log if t >= log[-1][0] - 10]
    assert all(abs(d - REF) < BAND for d in last), (min(last), max(last))
