"""Array ports in ``export ros``: the obstacle course (a lidar and a ReactiveAvoider), lockstep.

``scenarios/obstacle_course.yaml`` (issue 16's worked example) is exported, built with catkin
and launched in lockstep for its first 12 s: the lidar's 31 ranges travel from the simulator
(where the Lidar casts its rays into the pymunk world) to the ReactiveAvoider's node as one
``std_msgs/Float64MultiArray`` topic, ``/Scanner/ranges``. The trace and metrics must equal
``amsa-phys run --duration 12`` byte for byte with the C++ ReactiveAvoider (the default) and
with its Python twin (``cpp:=false``). Mutation-checked: the C++ body's beam directions
computed as ``k * delta / div + lo`` instead of numpy's ``k * step + lo`` (last-bit
differences) fails the C++ case (``tests/ros/test_cpp_avoider.py`` compares the body with
the template bit for bit on random scans, where rarer differences show).

With ``sim:=false`` a robot of the test's own publishes a 360-beam ``sensor_msgs/LaserScan``
(plus GPS fixes and a compass): the boundary fits it to the lidar's 31 beams and the pilot
steers the robot round a post to its goal (mutation-checked: with the fitted scan
mirrored, beam i from beam 30 - i, the robot stalls in front of the post, 8 m short).
Skipped, with the reason, where ROS, catkin, unshare or root is missing.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import ros_launch
from fakerobot import script
from ros_launch import Launch, build_workspace, ros_missing
from rosbags.highlevel import AnyReader

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "scenarios" / "obstacle_course.yaml"
PKG = "obstacleCourse"  # the world's name
DURATION = "12"  # s: past the first obstacle (the avoider turns), a few seconds of launch

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The exported obstacle course, built with catkin in a fresh workspace."""
    return build_workspace(tmp_path_factory.mktemp("ws"), SCENARIO, PKG)


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``amsa-phys run`` of the same scenario and duration, in-process."""
    out = tmp_path_factory.mktemp("ref") / "run"
    args = ["--headless", "--out", str(out), "-q", "--no-plot", "--duration", DURATION]
    assert main(["run", str(SCENARIO), *args]) == 0
    return out


def test_the_avoider_is_a_cpp_leaf_reading_one_array_topic(workspace: Path) -> None:
    src = workspace / "src" / PKG
    assert (src / "src" / "leaves" / "ReactiveAvoider.cpp").is_file()
    assert (workspace / "devel" / "lib" / f"lib{PKG}_leaves.so").is_file()
    wiring = (src / "config" / "amsa_leaves.yaml").read_text()
    assert "topic /Scanner/ranges 0x0.0p+0 0 31" in wiring  # an array topic of 31 values
    assert "/Scanner/ranges [31]" in (src / "nodes" / "Pilot.py").read_text()


@pytest.mark.parametrize("cpp", ["true", "false"])
def test_lockstep_reproduces_the_obstacle_course_with_cpp_and_python_avoider(
    workspace: Path, reference: Path, launcher: Callable[..., Launch], cpp: str
) -> None:
    out = workspace / f"lockstep_cpp_{cpp}"
    bag = workspace / f"data_{cpp}.bag"
    args = [f"out:={out}", "plots:=false", f"cpp:={cpp}", f"duration:={DURATION}", f"bag:={bag}"]
    text = launcher(workspace, "obstacle_course.launch", *args).finish()
    assert "partial" in text or "completed" in text, text[-3000:]
    assert (out / "trace.csv").read_bytes() == (reference / "trace.csv").read_bytes()
    assert ros_launch.metrics_without_wall(out) == ros_launch.metrics_without_wall(reference)
    # bag:= records the array topic: every scan, whole, as the trace has it
    trace = np.genfromtxt(reference / "trace.csv", delimiter=",", names=True)
    rows = {tuple(trace[f"Scannerranges{i}"][k] for i in range(31)) for k in range(len(trace))}
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.topic == "/Scanner/ranges"]
        assert [c.msgtype for c in conns] == ["std_msgs/msg/Float64MultiArray"]
        scans = [reader.deserialize(raw, conns[0].msgtype) for _, _, raw in reader.messages(conns)]
    assert len(scans) > 10 * int(DURATION)  # a scan every 0.1 s
    dim = scans[0].layout.dim
    assert [(d.label, d.size, d.stride) for d in dim] == [("ranges", 31, 31)]
    assert {tuple(s.data.tolist()) for s in scans} == rows - {(0.0,) * 31}


#: A robot of the test's own (plain rospy, no amsa-phys code) in an open field: a post of
#: radius 1 m at (44, 0.3) between it (at x = 38) and the pilot's goal (50, 0). A 360-beam
#: lidar over the full circle (its own ray casts, ``inf`` where nothing echoes, as drivers
#: publish), GPS fixes on the package's documented WGS 84 origin, the compass as Imu
#: orientation; it obeys the JointState efforts (% of full power, 5.5 m/s at 100 %).
ROBOT = script(
    "/Rover/wheel_cmd",
    "from sensor_msgs.msg import LaserScan",
    """
    POST, R, GOAL = (44.0, 0.3), 1.0, (50.0, 0.0)
    BEAMS, FAR = 360, 12.0

    def ray(x, y, a):
        dx, dy = math.cos(a), math.sin(a)
        px, py = x - POST[0], y - POST[1]
        b = dx * px + dy * py
        disc = b * b - (px * px + py * py - R * R)
        if disc < 0:
            return math.inf
        t = -b - math.sqrt(disc)
        return t if 0 < t <= FAR else math.inf

    gps = rospy.Publisher("/Rover/Gps/fix", NavSatFix, queue_size=10)
    compass = rospy.Publisher("/Rover/Heading/heading", Imu, queue_size=10)
    lidar = rospy.Publisher("/Rover/Scanner/scan", LaserScan, queue_size=10)
    x, y, th = 38.0, 0.0, 0.0
    clearance, k = math.inf, 0
    """,
    """
    clearance = min(clearance, math.hypot(x - POST[0], y - POST[1]) - R)
    k += 1
    if k % 2:
        continue  # sensors at 10 Hz
    fix(gps, x, y, now, "Rover/base_link", covariance=False)
    heading(compass, th, now, "Rover/base_link")
    scan = LaserScan()
    scan.header.stamp, scan.header.frame_id = now, "Rover/base_link"
    scan.angle_min, scan.angle_increment = -math.pi, 2 * math.pi / BEAMS
    scan.angle_max = scan.angle_min + (BEAMS - 1) * scan.angle_increment
    scan.range_min, scan.range_max = 0.15, FAR
    scan.ranges = [ray(x, y, th + scan.angle_min + i * scan.angle_increment) for i in range(BEAMS)]
    lidar.publish(scan)
    if t - t0 >= END or math.hypot(x - GOAL[0], y - GOAL[1]) < 0.6:
        break
    """,
    '{"x": x, "y": y, "clearance": clearance, "commands": commands[0], "t": t - t0}',
)


def test_sim_false_the_pilot_steers_a_robot_round_a_post_by_its_own_laserscan(
    workspace: Path, launcher: Callable[..., Launch]
) -> None:
    """``sim:=false``: the boundary fits the robot's 360-beam LaserScan to the lidar Leaf's 31
    beams (``ros/runtime/arrays.py`` ``fit_scan``) on ``/Scanner/ranges``; the C++ pilot
    steers round the post and reaches the goal."""
    pkg = workspace / "src" / PKG
    robot = pkg / "test_robot.py"
    robot.write_text(ROBOT)
    robot.chmod(0o755)
    result = workspace / "robot.json"
    (pkg / "launch" / "robot.launch").write_text(
        "<launch>\n"
        f'  <include file="$(find {PKG})/launch/obstacle_course.launch">\n'
        '    <arg name="sim" value="false"/>\n'
        '    <arg name="speed" value="2"/>\n'
        "  </include>\n"
        f'  <node pkg="{PKG}" type="test_robot.py" name="test_robot" required="true"'
        f' args="30 {result}" output="screen"/>\n'
        "</launch>\n"
    )
    text = launcher(workspace, "robot.launch").finish()
    assert result.exists(), text[-3000:]
    data = json.loads(result.read_text())
    assert data["commands"] > 50, text[-3000:]
    assert "amsa_simulator" not in text.split("NODES")[1].split("auto-starting")[0]
    assert math.hypot(data["x"] - 50.0, data["y"]) < 0.6, data  # at the goal
    assert data["clearance"] > 0.25, data  # round the post, never touching it (half a rover)
