"""The exported ROS 2 package on a robot: ``amsa-phys ros2 robot`` (the launch's ``sim:=false``).

The sensed MDE world (the controller's distance from the two GPS fixes) is exported and its
controller side started with the robot boundary, no simulator. A fake robot of the test's
own (``robot_node.py``: plain rclpy, the standard messages, the sensor-data QoS) publishes
``NavSatFix`` for both receivers and the compass's ``Imu`` for scripted scenes and reads the
``JointState`` wheel commands: each must be the paper's follower law, clamped and scaled by
the actuator, computed here from the poses the robot published. Hostile driver messages (a
NaN latitude, another frame, an orientation not provided, another message type) each give
the boundary's documented one line and never reach a data topic. Everything runs with
``.venv-ros2``'s python in ``unshare -n`` (``ros2net.py``).
"""

from __future__ import annotations

import ast
import json
import math
import os
import random
import subprocess
import uuid
from pathlib import Path

import pytest
from ros2net import (
    PY,
    ROOT,
    WALL_LIMIT_S,
    in_private_network,
    leftovers,
    ros2_missing,
    without_rclpy_task_noise,
)

pytestmark = pytest.mark.ros2
MISSING = ros2_missing()
if MISSING:
    pytest.skip(MISSING, allow_module_level=True)

ROBOT = Path(__file__).resolve().parent / "robot_node.py"
ENV = {"SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "PYTHONUNBUFFERED": "1"}
#: the follower law's parameters, set by the test's scenario (Kff stays 0: no feed-forward)
KV, KW, REF, COEF = 0.05, 0.3, 15.0, 80
SCENARIO = f"""name: robot_check
world: {ROOT / "worlds" / "mde_challenge_sensed.yaml"}
duration: 10
seed: 1
set: {{MyFollowerController.Kv: {KV}, MyFollowerController.Kw: {KW},
      MyFollowerController.distanceRef: {REF}, MyNormalizePower.motorCoef: {COEF}}}
"""
#: (leader x, y, follower x, y, heading): ahead, too close, to the left, to the right, far
SCENES = [
    (20.0, 0.0, 0.0, 0.0, 0.0),
    (10.0, 0.0, 0.0, 0.0, 0.0),
    (18.0, 9.0, 2.0, 1.0, 0.3),
    (30.0, -12.0, 1.0, 2.0, 0.4),
    (400.0, 30.0, 0.0, 0.0, 0.0),
]


def follower_law(lx: float, ly: float, fx: float, fy: float, h: float) -> tuple[float, float]:
    """The paper's proportional law (no feed-forward), then the actuator's clamp and share."""
    d = math.hypot(lx - fx, ly - fy)
    alpha = math.atan2(ly - fy, lx - fx) - h
    alpha = (alpha + math.pi) % (2 * math.pi) - math.pi
    forward = 100 * KV * (d - REF) * math.cos(alpha)
    turn = 100 * KW * alpha
    return tuple(min(100.0, max(-100.0, p)) * COEF / 100 for p in (forward - turn, forward + turn))  # type: ignore[return-value]


def export(tmp: Path, scenario: Path | None = None) -> Path:
    if scenario is None:
        scenario = tmp / "robot_check.yaml"
        scenario.write_text(SCENARIO)
    pkg = tmp / "pkg"
    subprocess.run(
        [PY, "-m", "amsa_phys", "export", "ros2", str(scenario), "-o", str(pkg)],
        check=True,
        capture_output=True,
        env={**os.environ, **ENV},
    )
    return pkg


def on_robot(
    tmp: Path, pkg: Path, robot_args: list[str], robot: Path = ROBOT
) -> tuple[int, str, str, list[int]]:
    """``amsa-phys ros2 robot PKG`` and the fake robot in a private network; the robot's end
    stops amsa-phys (SIGTERM). Returns amsa-phys's exit status, its output, the log of
    everything, and the processes left behind."""
    amsa_log, log = tmp / "amsa.log", tmp / "all.log"
    script = tmp / "robot.sh"
    script.write_text(
        "set -m\nip link set lo up\n"  # job control: the background job keeps its SIGINT
        f"{PY} -m amsa_phys ros2 robot {pkg} --speed 4 >{amsa_log} 2>&1 & AMSA=$!\n"
        f"{PY} {robot} {' '.join(robot_args)}\n"
        "kill -TERM $AMSA; wait $AMSA; echo AMSA_RC=$?\n"
    )
    _, left = in_private_network(script, ENV, log)
    text = log.read_text()
    rc_lines = [x for x in text.splitlines() if x.startswith("AMSA_RC=")]
    rc = int(rc_lines[-1].partition("=")[2]) if rc_lines else -1
    return rc, amsa_log.read_text() if amsa_log.exists() else "", text, left


@pytest.fixture(scope="module")
def robot_run(tmp_path_factory: pytest.TempPathFactory) -> dict:
    tmp = tmp_path_factory.mktemp("robot")
    pkg = export(tmp)
    scenes, out = tmp / "scenes.json", tmp / "robot.json"
    scenes.write_text(json.dumps(SCENES))
    rc, amsa_out, text, left = on_robot(tmp, pkg, [str(scenes), str(out)])
    assert out.exists(), amsa_out + text[-4000:]
    return {
        "rc": rc,
        "amsa": amsa_out,
        "text": text,
        "left": left,
        **json.loads(out.read_text()),
    }


def test_the_wheel_commands_are_the_follower_law_of_the_published_poses(robot_run: dict) -> None:
    got = robot_run["scenes"]
    assert [s["scene"] for s in got] == [list(s) for s in SCENES]
    for s in got:
        assert s["effort"] is not None, (s, robot_run["amsa"][-3000:])
        want = follower_law(*s["scene"])
        # the fixes went through latitude and longitude: a micrometre, not more
        assert s["effort"] == pytest.approx(want, abs=1e-6), (s["scene"], s["effort"], want)
    ahead, close, left, right, far = (s["effort"] for s in got)
    assert ahead[0] == ahead[1] > 0  # leader straight ahead, too far: both wheels forward
    assert close[0] == close[1] < 0  # too close: both back
    assert left[1] > left[0]  # leader to the left: the right wheel pushes harder
    assert right[0] > right[1]
    assert far == [100 * (COEF * 0.01)] * 2  # far off: both clamped at 100 %, then scaled


def test_a_command_is_a_joint_state_of_both_wheels_in_percent(robot_run: dict) -> None:
    names, _, frame, _ = robot_run["commands"][-1]
    assert names == ["left_wheel_joint", "right_wheel_joint"]
    assert frame == "Follower/base_link"
    stamps = [c[3] for c in robot_run["commands"]]
    assert stamps == sorted(stamps)  # stamped with the boundary's /clock
    assert "/Follower/wheel_cmd  sensor_msgs/msg/JointState" in robot_run["amsa"]


def test_hostile_driver_messages_give_one_line_each_and_never_reach_the_controller(
    robot_run: dict,
) -> None:
    said = [m for _, m in robot_run["said"]]
    for line in [
        "dropped sensor_msgs/msg/NavSatFix on /Leader/LeaderGPS/fix: latitude is nan",
        "dropped sensor_msgs/msg/NavSatFix on /Leader/LeaderGPS/fix: "
        "frame_id 'gps_link', expected 'Leader/base_link'",
        "dropped sensor_msgs/msg/Imu on /Follower/FollowerCompass/heading: "
        "orientation not provided (orientation_covariance[0] = -1)",
        "hostile_driver publishes std_msgs/msg/String on /Leader/LeaderGPS/fix, "
        "expected sensor_msgs/msg/NavSatFix: its messages are not read",
    ]:
        assert line in said, said
        assert said.count(line) == 1  # a stream of them: one line per new reason
    seen = robot_run["seen"]
    assert all(math.isfinite(v) for vs in seen.values() for v in vs)
    assert max(seen["/LeaderGPS/gpsPosX"]) < 500  # the fix 1000 m away in another frame
    assert 2.0 not in seen["/FollowerCompass/compassHeading"]  # the orientation not provided
    after = robot_run["after"]
    assert after, robot_run["amsa"][-3000:]
    assert after[-1] == pytest.approx(follower_law(*SCENES[-1]), abs=1e-6)


def test_the_robot_side_stops_cleanly(robot_run: dict) -> None:
    assert robot_run["rc"] == 0, robot_run["amsa"][-3000:]
    assert "robot side: MyGpsDistance, MyFollowerController, MyNormalizePower" in robot_run["amsa"]
    assert "Traceback" not in without_rclpy_task_noise(robot_run["text"])
    assert robot_run["left"] == []


def _launch_nodes(pkg: Path) -> dict[str, str]:
    """Each Node of the launch file by executable: its condition's class, or ``""``."""
    (launch,) = (pkg / "launch").glob("*.launch.py")
    nodes: dict[str, str] = {}
    for call in ast.walk(ast.parse(launch.read_text())):
        if isinstance(call, ast.Call) and getattr(call.func, "id", "") == "Node":
            kw = {k.arg: k.value for k in call.keywords}
            exe = kw["executable"]
            cond = kw.get("condition")
            assert isinstance(exe, ast.Constant)
            nodes[exe.value] = cond.func.id if isinstance(cond, ast.Call) else ""  # type: ignore[attr-defined]
    return nodes


def test_the_launch_files_sim_false_starts_the_controller_side_and_the_boundary(
    tmp_path: Path,
) -> None:
    nodes = _launch_nodes(export(tmp_path))
    always = sorted(n for n, c in nodes.items() if c == "")
    assert always == ["MyFollowerController", "MyGpsDistance", "MyNormalizePower"]
    assert nodes["amsa_boundary"] == "UnlessCondition"  # sim:=false only
    sim_only = {"LeaderGPS", "FollowerGPS", "FollowerCompass", "MyDistanceMonitor"}
    assert {n for n, c in nodes.items() if c == "IfCondition"} == sim_only


def test_every_sensor_stream_reaches_its_data_topics(tmp_path: Path) -> None:
    """The obstacle course's rover: a LaserScan, a NavSatFix, the compass's and an IMU's Imu,
    a wheel odometry's Odometry, each in its documented frame, become the values the Leaves
    would output; the pilot (ReactiveAvoider) then commands the wheels."""
    pkg = export(tmp_path, ROOT / "scenarios" / "obstacle_course.yaml")
    out = tmp_path / "streams.json"
    rc, amsa_out, text, left = on_robot(
        tmp_path, pkg, [str(out)], Path(__file__).resolve().parent / "streams_node.py"
    )
    assert out.exists(), amsa_out + text[-4000:]
    got = json.loads(out.read_text())
    last = got["last"]
    want = {
        "/Gps/gpsPosX": 4.0,
        "/Gps/gpsPosY": -1.5,
        "/Heading/compassHeading": 0.7,
        "/Odometry/odomX": 3.0,
        "/Odometry/odomY": -2.0,
        "/Odometry/odomHeading": -0.4,
        "/Imu/gyroZ": 0.25,
        "/Imu/accelX": 0.5,
        "/Imu/accelY": -0.1,
    }
    for topic, value in want.items():
        assert last.get(topic) == pytest.approx(value, abs=1e-6), (topic, last, amsa_out)
    assert last["/Scanner/ranges"] == got["ranges"]  # the declared beams: beam for beam
    assert len(got["commands"]) >= 3, amsa_out
    assert "robot side: Pilot, Drive" in amsa_out
    assert rc == 0, amsa_out
    assert left == []


def test_a_controller_node_that_exits_stops_the_robot_side_with_one_line(tmp_path: Path) -> None:
    pkg = export(tmp_path)
    node = pkg / "mde_challenge_sensed" / "MyNormalizePower.py"
    # it dies once the boundary, started last, is on the graph: every node is running
    dying = (
        "def main():\n"
        "    import rclpy\n"
        "    rclpy.init()\n"
        "    n = rclpy.create_node('dying')\n"
        "    while 'amsa_boundary' not in n.get_node_names():\n"
        "        rclpy.spin_once(n, timeout_sec=0.1)\n"
        "    raise SystemExit(7)\n\n\n"
        "def _main():"
    )
    node.write_text(node.read_text().replace("def main():", dying))
    token = uuid.uuid4().hex
    env = {**os.environ, **ENV, "AMSA_ROS2_TEST": token}
    env["ROS_DOMAIN_ID"] = str(random.randint(1, 100))
    env.pop("VIRTUAL_ENV", None)
    res = subprocess.run(
        ["unshare", "-n", "bash", "-c", f"ip link set lo up\n{PY} -m amsa_phys ros2 robot {pkg}"],
        env=env,
        capture_output=True,
        text=True,
        timeout=WALL_LIMIT_S,
    )
    assert res.returncode == 2, res.stdout + res.stderr
    errors = [line for line in res.stderr.splitlines() if line.startswith("error:")]
    assert errors == ["error: ROS 2 node MyNormalizePower exited with status 7"], res.stderr
    assert "Traceback" not in without_rclpy_task_noise(res.stderr)
    assert leftovers(token) == []


@pytest.mark.parametrize(
    ("scenario", "args", "says"),
    [
        ("scenario1.yaml", [], "no node of this package can run on a robot"),
        ("paper_fig6_sensed.yaml", ["--speed", "0"], "--speed: expected a positive number"),
        ("paper_fig6_sensed.yaml", ["--speed", "nan"], "--speed: expected a positive number"),
    ],
)
def test_a_package_without_a_robot_side_or_a_bad_speed_is_one_line(
    tmp_path: Path, scenario: str, args: list[str], says: str
) -> None:
    pkg = export(tmp_path, ROOT / "scenarios" / scenario)
    res = subprocess.run(
        [PY, "-m", "amsa_phys", "ros2", "robot", str(pkg), *args],
        capture_output=True,
        text=True,
        env={**os.environ, **ENV},
        timeout=WALL_LIMIT_S,
    )
    assert res.returncode == 2, res.stdout + res.stderr
    assert len(res.stderr.splitlines()) == 1, res.stderr
    assert says in res.stderr


def test_the_controller_drives_a_robot_in_closed_loop(tmp_path: Path) -> None:
    """The robot obeys the commands with its own kinematics behind its own leader (straight at
    0.2 m/s, 25 m ahead): after 40 s of the boundary's /clock the follower has caught up and
    holds the band (15 ± 1.5 m, the scenario family's tolerance)."""
    pkg = export(tmp_path)
    out = tmp_path / "drive.json"
    rc, amsa_out, text, left = on_robot(
        tmp_path, pkg, ["40", str(out)], Path(__file__).resolve().parent / "drive_node.py"
    )
    assert out.exists(), amsa_out + text[-4000:]
    got = json.loads(out.read_text())
    log = got["log"]
    assert got["commands"] > 50, amsa_out  # obeyed commands all along
    assert log[0][1] > 24.0  # it started 10 m too far
    assert log[-1][2] > 15.0, log[-1]  # it moved: 10 m closed, and the leader drove 8 m on
    last = [d for t, d, _, _ in log if t >= log[-1][0] - 10]
    assert all(abs(d - REF) < 1.5 for d in last), (min(last), max(last))
    assert rc == 0, amsa_out
    assert left == []


@pytest.mark.parametrize("param", ["speed:=-1.0", "speed:=inf", "check_frames:=maybe"])
def test_the_boundary_node_refuses_a_bad_parameter_in_one_line(tmp_path: Path, param: str) -> None:
    """What a launch argument gives the node (``speed:=``, ``check_frames:=``) is judged."""
    pkg = export(tmp_path)
    script = pkg / "mde_challenge_sensed" / "amsa_boundary.py"
    env = {**os.environ, **ENV, "ROS_DOMAIN_ID": str(random.randint(1, 100))}
    env.pop("VIRTUAL_ENV", None)
    res = subprocess.run(
        ["unshare", "-n", "bash", "-c", f"ip link set lo up\n{PY} {script} --ros-args -p {param}"],
        env=env,
        capture_output=True,
        text=True,
        timeout=WALL_LIMIT_S,
    )
    assert res.returncode == 2, res.stdout + res.stderr
    lines = res.stderr.splitlines()
    assert len(lines) == 1, res.stderr
    assert lines[0].startswith("error: amsa_boundary: speed must be a positive number and ")
    name, _, value = param.partition(":=")
    assert f"{name}={value!r}" in lines[0] or f"{name}={float(value)!r}" in lines[0], lines
