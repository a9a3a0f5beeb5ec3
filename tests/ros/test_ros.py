"""``amsa-phys export ros`` for real: build with catkin, launch with roslaunch, compare.

The package of a 30 s scenario1 (with timeline changes inside the run) is built once for the
session (``ros_short_workspace`` in conftest.py, shared with test_ros_boundary_stamps.py); then:
lockstep reproduces ``amsa-phys run`` byte for byte (trace.csv, metrics.json but its wall
time, scenario.yaml) and a bag of the Data topics holds the trace's values; free mode comes
within stated bounds of the in-process metrics; Ctrl-C on roslaunch stops every process and
writes the outputs so far. Every launch runs in a private network namespace (``unshare -n``:
roscpp listens on all interfaces) and every process it starts carries a token in its
environment, so the test can prove none is left behind (and end stragglers by their id).
Skipped, with the reason, where ROS, catkin, unshare or root is missing.
"""

from __future__ import annotations

import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, assert_bag_holds_the_trace, package_edit, ros_missing

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "ros_short.yaml"
PKG = "mdeChallenge"

#: Free mode against the in-process run (same scenario and seed), in metres. Free mode's
#: latency differs (each node samples its inputs at its own timer's phase instead of the
#: schedule's order) and varies run to run; measured deviations on this machine were at
#: most ~0.15 m on these metrics (report in the README). The bounds leave room for a loaded
#: CI machine, and are still far tighter than the metrics' own spread across Kv values.
FREE_BOUNDS = {"max_distance": 1.0, "final_distance": 1.0, "mean_error": 0.5}


pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture


@pytest.fixture(scope="module")
def workspace(ros_short_workspace: Path) -> Path:
    """The exported package, built (and installed) with catkin once for the session: a test
    edits it only through ``package_edit`` and writes its outputs in its own ``tmp_path``."""
    return ros_short_workspace


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``amsa-phys run`` of the same scenario, in-process."""
    out = tmp_path_factory.mktemp("ref") / "run"
    assert main(["run", str(SCENARIO), "--headless", "--out", str(out), "-q", "--no-plot"]) == 0
    return out


_metrics = ros_launch.metrics_without_wall


def test_lockstep_reproduces_amsa_phys_run(
    workspace: Path, reference: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    out = tmp_path / "lockstep"
    bag = tmp_path / "lockstep.bag"
    t0 = time.perf_counter()
    launch = launcher(workspace, "ros_short.launch", f"out:={out}", "plots:=false", f"bag:={bag}")
    text = launch.finish()
    print(f"lockstep launch to done: {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    assert "completed" in text, text[-3000:]
    # a passing run ends as a clean shutdown: the simulator's last line says done, and
    # roslaunch does not announce, in red, that a required process died
    assert "amsa_simulator: done: 1 expectation passed" in text, text[-3000:]
    assert "REQUIRED process" not in text, text[-3000:]
    assert launch.proc.returncode == 0
    assert (out / "trace.csv").read_bytes() == (reference / "trace.csv").read_bytes()
    assert _metrics(out) == _metrics(reference)
    assert (out / "scenario.yaml").read_text() == (reference / "scenario.yaml").read_text()
    # the bag: on every Data topic, the values the trace shows, in the same order (the
    # trace samples every 0.05 s, faster than any Leaf publishes, so it sees each message
    # that changes a value). A delayed Leaf's (the controller's 0.75 s latency, the follower
    # GPS's jitter) messages reach the trace later: the last ones, still in flight when the
    # run ends, are in the bag only
    world = load_scenario(SCENARIO).world
    delayed = {p for p, leaf in world.leaves.items() if leaf.timing.delayed}
    assert delayed == {"MyFollowerController", "FollowerGPS"}
    extra = assert_bag_holds_the_trace(bag, reference / "trace.csv", delayed)
    assert max(extra.values()) <= 3, extra  # 0.75 s at 4 Hz: 3 in flight


def test_free_mode_metrics_within_bounds(
    workspace: Path, reference: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    out = tmp_path / "free"
    t0 = time.perf_counter()
    # at real time (speed:=1): the run lasts its 30 s, while each edit below starts a Python
    # process (rosparam) that takes seconds on a loaded machine; at speed:=4 (7.5 s) a loaded
    # CI run ended before the first edit landed
    launch = launcher(
        workspace, "ros_short.launch", f"out:={out}", "plots:=false", "mode:=free", "speed:=1"
    )
    assert launch.read_until("running ros_short"), "".join(launch.lines)[-3000:]
    # live edits, as a user would make them (in the launch's network namespace): one the
    # simulator takes (steering gain: no effect on a straight-driving leader), one a node
    # refuses (out of the template's range)
    for name, value in (("/Leader/steerGain", "30.0"), ("/MyFollowerController/Kv", "20")):
        edit = subprocess.run(
            ["nsenter", "-t", str(launch.proc.pid), "-n", "rosparam", "set", name, value],
            capture_output=True,
            text=True,
            env={**os.environ, "ROS_MASTER_URI": "http://localhost:11311"},
        )
        assert edit.returncode == 0, edit.stderr
    text = launch.finish()
    print(f"free launch to done: {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    assert "completed" in text, text[-3000:]
    free, ref = _metrics(out), _metrics(reference)
    deviations = {k: abs(free["overall"][k] - ref["overall"][k]) for k in FREE_BOUNDS}
    print(f"free mode deviations: {deviations}", file=sys.stderr)
    for key, bound in FREE_BOUNDS.items():
        assert deviations[key] < bound, (key, free["overall"][key], ref["overall"][key])
    assert free["overall"]["collisions"] == 0
    live = [e["detail"] for e in json.loads((out / "metrics.json").read_text())["events"]]
    assert live == ["Leader.steerGain=30.0"]
    logs = "".join(p.read_text() for p in (workspace / "roshome" / "log").rglob("*.log"))
    assert "/MyFollowerController/Kv: 20 is above the maximum 10" in logs
    # the scenario node's change of the C++ node's motorCoef (100 -> 80 at t = 46/3 s) took
    # effect: a delivered power is a commanded one times 1.0 before, times 0.8 after. The
    # trace samples both topics at its own rate, so a command the node took may never have
    # been sampled (on a loaded machine the controller can publish twice between two rows):
    # nearly every row, not every one, shows the commanded value it was delivered from
    rows = list(csv.reader((out / "trace.csv").open()))
    col = {c: i for i, c in enumerate(rows[0])}
    commanded = {float(r[col["MyFollowerController.LeftPower"]]) for r in rows[1:]}

    def share(coef: float, keep: Callable[[float, float], bool]) -> tuple[float, int]:
        """(share of the kept rows whose delivered power is a commanded one times coef,
        kept rows)"""
        kept = [
            float(r[col["MyNormalizePower.normalizedPowerL"]])
            for r in rows[1:]
            if keep(float(r[0]), float(r[col["MyNormalizePower.normalizedPowerL"]]))
        ]
        hits = sum(any(min(100.0, max(-100.0, u)) * coef == d for u in commanded) for d in kept)
        return hits / max(1, len(kept)), len(kept)

    before, n_before = share(1.0, lambda t, d: t < 15.2 and d != 0.0)
    after, n_after = share(0.8, lambda t, d: t > 17.0)  # taken at the node's next step
    assert n_before >= 10, n_before
    assert n_after >= 10, n_after
    assert before >= 0.9, before
    assert after >= 0.9, after
    assert share(1.0, lambda t, d: t > 17.0 and d != 0.0)[0] <= 0.1  # not the old coefficient


def test_ctrl_c_stops_every_node_and_keeps_the_outputs(
    workspace: Path, reference: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    out = tmp_path / "interrupted"
    launch = launcher(
        workspace, "ros_short.launch", f"out:={out}", "plots:=false", "duration:=3600"
    )
    # the scenario node says so when it applies the change at t = 10 s
    assert launch.read_until("phase 1 at t=10 s"), "".join(launch.lines)[-3000:]
    os.killpg(launch.proc.pid, signal.SIGINT)  # what a terminal's Ctrl-C sends
    launch.finish()  # fails if any process of the launch is left
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "interrupted"
    rows = (out / "trace.csv").read_text().splitlines()
    ref = (reference / "trace.csv").read_text().splitlines()
    assert len(rows) > 10 * 20  # at least the 10 s before the phase
    n = min(len(rows), len(ref))
    assert rows[:n] == ref[:n]


def _rosparam(launch: Launch, *args: str) -> str:
    """``rosparam ARGS`` in the launch's network namespace; its output."""
    done = subprocess.run(
        ["nsenter", "-t", str(launch.proc.pid), "-n", "rosparam", *args],
        capture_output=True,
        text=True,
        env={**os.environ, "ROS_MASTER_URI": "http://localhost:11311"},
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def _same_run(out: Path, ref: Path) -> None:
    assert (out / "trace.csv").read_bytes() == (ref / "trace.csv").read_bytes()
    assert _metrics(out) == _metrics(ref)
    assert (out / "scenario.yaml").read_text() == (ref / "scenario.yaml").read_text()


def test_an_edited_params_file_is_what_runs_and_what_is_recorded(
    workspace: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    """Issue 33 item 7: Kv edited in config/*_params.yaml ran, but scenario.yaml said 0.1.
    The run now equals ``amsa-phys run --set MyFollowerController.Kv=0.2``, records included."""
    params = workspace / "src" / PKG / "config" / "ros_short_params.yaml"
    original = params.read_text()
    edited = original.replace(
        "MyFollowerController:\n  Kv: 0.1\n", "MyFollowerController:\n  Kv: 0.2\n"
    )
    assert edited != original
    out = tmp_path / "edited"
    with package_edit(params, edited):
        text = launcher(workspace, "ros_short.launch", f"out:={out}", "plots:=false").finish()
    assert "completed" in text, text[-3000:]
    assert "MyFollowerController.Kv=0.2 (parameter server)" in text
    ref = tmp_path / "ref"
    argv = ["run", str(SCENARIO), "--headless", "--out", str(ref), "-q", "--no-plot"]
    assert main([*argv, "--set", "MyFollowerController.Kv=0.2"]) == 0
    _same_run(out, ref)


def test_duration_argument_cuts_the_run_as_run_duration_does(
    workspace: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    """``duration:=12.5`` stops inside phase 1: partial, its checks skipped, as ``run``
    (the ROS simulator had its own cut, which judged the cut phase as if complete)."""
    out = tmp_path / "cut"
    text = launcher(
        workspace, "ros_short.launch", f"out:={out}", "plots:=false", "duration:=12.5"
    ).finish()
    assert "completed, simulated 12.5 s" in text, text[-3000:]
    ref = tmp_path / "ref"
    argv = ["run", str(SCENARIO), "--headless", "--out", str(ref), "-q", "--no-plot"]
    assert main([*argv, "--duration", "12.5"]) == 0
    _same_run(out, ref)
    phases = json.loads((out / "metrics.json").read_text())["phases"]
    assert [p.get("partial") for p in phases] == [None, True]  # the cut phase: not judged


def test_free_mode_live_edits_are_events_and_refused_ones_are_put_back(
    workspace: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    """A ``rosparam set`` of a node's parameter is an event of the run; a refused value does
    not stay on the parameter server. Waits for each effect, then stops with Ctrl-C."""
    out = tmp_path / "live"
    launch = launcher(
        workspace,
        "ros_short.launch",
        f"out:={out}",
        "plots:=false",
        "mode:=free",
        "duration:=3600",
    )
    assert launch.read_until("running ros_short"), "".join(launch.lines)[-3000:]
    kv = "/MyFollowerController/Kv"
    _rosparam(launch, "set", kv, "99")  # above the template's maximum (10)
    while _rosparam(launch, "get", kv) == "99":  # put back by whoever judges it first
        assert launch.proc.poll() is None, "".join(launch.lines)[-3000:]
    # the value in force: 0.1, or 0.05 if the timeline's t = 10 change landed meanwhile (a
    # loaded machine's rosparam calls take seconds)
    assert float(_rosparam(launch, "get", kv)) in (0.1, 0.05)
    _rosparam(launch, "set", kv, "0.2")
    assert launch.read_until("live change MyFollowerController.Kv=0.2"), "".join(launch.lines)
    os.killpg(launch.proc.pid, signal.SIGINT)
    launch.finish()
    events = json.loads((out / "metrics.json").read_text())["events"]
    live = [e["detail"] for e in events if e["kind"] == "live change"]
    assert live[0] == "MyFollowerController.Kv=0.2"
    assert not any("99" in e["detail"] for e in events)
    assert "MyFollowerController.Kv" in (out / "scenario.yaml").read_text().split("timeline")[1]


def test_a_moved_workspace_still_reproduces_the_run(
    workspace: Path, tmp_path: Path, reference: Path, launcher: Callable[..., Launch]
) -> None:
    """Issue 26: the package names no path of the machine that made it. Built and installed
    (``catkin_make install``: the session's workspace is), the workspace's sources and
    install space are copied to another directory, the original workspace is gone (renamed
    away for the launch, put back after it), and the copy is launched with the target's
    Python settings only: lockstep still reproduces ``amsa-phys run`` byte for byte."""
    moved = tmp_path / "elsewhere" / "ws"
    for space in ("src", "install"):  # only the installed package is used: no build, devel
        shutil.copytree(workspace / space, moved / space, symlinks=True)
    (moved / "launch.sh").write_text(
        "set -e\nip link set lo up\n"
        f"export ROS_LOG_DIR={moved}/roshome/log ROS_MASTER_URI=http://localhost:11311\n"
        "export ROS_HOSTNAME=localhost ROS_DISTRO=${ROS_DISTRO:-debian}\n"
        f"source {moved}/install/setup.bash\n"
        f'exec roslaunch {PKG} "$@"\n'
    )
    out = moved / "run"
    made = workspace.resolve()  # the directory itself (workspace may be a link to it)
    hidden = made.with_name(made.name + "-away")
    made.rename(hidden)
    try:
        text = launcher(moved, "ros_short.launch", f"out:={out}", "plots:=false").finish()
        assert not made.exists()
    finally:
        hidden.rename(made)
    assert "completed" in text, text[-3000:]
    assert (out / "trace.csv").read_bytes() == (reference / "trace.csv").read_bytes()
    assert _metrics(out) == _metrics(reference)


#: A user's own node standing in for MyDistanceMonitor: plain rospy, no amsa-phys, and no
#: ``/amsa/ready`` announcement (it only subscribes, steps on simulated time and publishes).
USER_MONITOR = """#!/usr/bin/python3
import math
import rospy
from std_msgs.msg import Float64

rospy.init_node("MyDistanceMonitor")
pos = {}
for key in ("Leader/posX", "Leader/posY", "Follower/posX", "Follower/posY"):
    rospy.Subscriber("/" + key, Float64, lambda m, k=key: pos.__setitem__(k, m.data))
pub = rospy.Publisher("/MyDistanceMonitor/distanceFollowerToLeader", Float64, queue_size=10)
rate = rospy.Rate(4)  # simulated time (use_sim_time)
while not rospy.is_shutdown():
    if len(pos) == 4:
        dx = pos["Leader/posX"] - pos["Follower/posX"]
        dy = pos["Leader/posY"] - pos["Follower/posY"]
        pub.publish(Float64(math.hypot(dx, dy)))
    try:
        rate.sleep()
    except rospy.ROSInterruptException:
        break
"""


def test_free_mode_waits_for_a_user_node_by_its_topics(
    workspace: Path, reference: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    """Issue 26: a node that does not announce itself on /amsa/ready made a free-mode run
    abort after 120 s. Here a user's monitor node replaces the generated one; the run starts
    once its topic is connected, completes, and keeps the follower in the in-process bounds."""
    pkg = workspace / "src" / PKG
    script = pkg / "user_monitor.py"
    launch_file = pkg / "launch" / "ros_short_user.launch"
    original = (pkg / "launch" / "ros_short.launch").read_text()
    # the Leaf's nodes (a C++ one alone with cpp_container:=false, its Python twin with
    # cpp:=false) give way to the user's node, and the Leaf leaves the C++ container's list
    common = 'pkg="mdeChallenge" name="MyDistanceMonitor" required="true"'
    alone = (
        "  <node if=\"$(eval arg('sim') and arg('cpp') and not arg('cpp_container'))\""
        ' pkg="nodelet" type="nodelet" args="standalone mdeChallenge/DistanceMonitor"'
        ' name="MyDistanceMonitor" required="true"/>\n'
    )
    py = f"  <node if=\"$(eval arg('sim') and not arg('cpp'))\" {common}"
    py += ' type="MyDistanceMonitor.py"/>'
    hosted = '"FollowerCompass", "MyDistanceMonitor", '
    assert alone + py in original
    assert hosted in original
    user = original.replace(alone + py, f'  <node {common} type="user_monitor.py"/>')
    out = tmp_path / "user-node"
    with (
        package_edit(script, USER_MONITOR),
        package_edit(launch_file, user.replace(hosted, '"FollowerCompass", ')),
    ):
        script.chmod(0o755)
        launch = launcher(
            workspace,
            "ros_short_user.launch",
            f"out:={out}",
            "plots:=false",
            "mode:=free",
            "speed:=4",
        )
        text = launch.finish()
    assert "running ros_short (free)" in text, text[-3000:]
    assert "completed" in text, text[-3000:]
    free, ref = _metrics(out), _metrics(reference)
    for key, bound in FREE_BOUNDS.items():
        assert abs(free["overall"][key] - ref["overall"][key]) < bound, key


def test_run_lockstep_exits_with_the_runs_verdict(
    workspace: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    """roslaunch exits 0 whatever the run's checks say; ``rosrun PKG run_lockstep`` exits 0
    when every expectation passes, 1 when one fails (here the leader cruises at 70 % in
    phase 0, edited in the params file, and the follower falls 25 m behind), 2 when the run
    does not even start (an out:= directory amsa-phys did not make)."""
    checked = ros_launch.run_lockstep_dir(workspace, PKG, tmp_path / "checked")
    passing = launcher(checked, "ros_short.launch", "plots:=false")  # out: runs/ in its cwd
    text = passing.finish()
    assert passing.proc.returncode == 0, text[-3000:]
    assert "run_lockstep: pass: 1 expectation passed" in text
    assert len(list((checked / "runs").glob("ros_short-*/metrics.json"))) == 1
    params = workspace / "src" / PKG / "config" / "ros_short_params.yaml"
    original = params.read_text()
    assert "  cruisePower: 7.0\n" in original
    with package_edit(params, original.replace("  cruisePower: 7.0\n", "  cruisePower: 70.0\n")):
        out = checked / "failing"
        failing = launcher(checked, "ros_short", f"out:={out}", "plots:=false")
        text = failing.finish()
    assert failing.proc.returncode == 1, text[-3000:]
    assert "expect max_distance (phase 0) = 25.28, below 17: FAIL" in text
    assert "run_lockstep: FAIL: 1 of 1 expectation failed" in text
    refused = launcher(checked, "ros_short.launch", f"out:={workspace / 'src'}", "plots:=false")
    text = refused.finish()
    assert refused.proc.returncode == 2, text[-3000:]
    assert "run_lockstep: no run in" in text


def test_a_simulator_that_cannot_start_is_the_one_error(
    workspace: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    """No AMSA_PHYS_PYTHON (amsa-phys not in ROS's python3): every Python node would say so;
    the simulator alone does, and roslaunch stops the rest without a word of theirs."""
    bare = tmp_path / "bare"
    bare.mkdir()
    script = (workspace / "launch.sh").read_text()
    (bare / "launch.sh").write_text("unset AMSA_PHYS_PYTHON\n" + script)
    text = launcher(bare, "ros_short.launch", "plots:=false").finish()
    assert text.count("cannot import amsa_phys") == 1, text[-3000:]
    assert "REQUIRED process [amsa_simulator-2] has died" in text, text[-3000:]
    assert "gave up" not in text


def test_a_leaf_without_simulator_says_what_it_waited_for(
    workspace: Path, launcher: Callable[..., Launch]
) -> None:
    """A C++ Leaf whose readers never come (here: no simulator nor scenario node in the
    launch file) names the topics short of subscribers, how long it waited, and points at
    the simulator's own error; it used to say "not connected after 120 s" and no more."""
    launch_dir = workspace / "src" / PKG / "launch"
    original = (launch_dir / "ros_short.launch").read_text()
    nosim = re.sub(r'  <node [^>]*type="amsa_simulator.py".*?</node>\n', "", original, flags=re.S)
    nosim = re.sub(r'  <node [^>]*type="amsa_scenario.py"[^>]*/>\n', "", nosim)
    assert "amsa_simulator.py" not in nosim
    assert "amsa_scenario.py" not in nosim
    with package_edit(launch_dir / "ros_short_nosim.launch", nosim):
        text = launcher(workspace, "ros_short_nosim.launch", "timeout:=1").finish()
    # the first C++ Leaf to give up ends its process (a required node), and the launch
    found = re.search(
        r"error: (/\w+): gave up after (\d+\.\d) s waiting for the readers of (.*)", text
    )
    assert found is not None, text[-3000:]
    _leaf, waited, rest = found.groups()
    assert float(waited) >= 2.0  # timeout:=1, twice that for the start
    assert "/amsa/done/amsa_leaves (0 of 1 subscribers)" in rest  # the container answers
    assert "; amsa_simulator reads each of them: if it did not start, its own error" in rest
