"""Free mode counts no sample of the quality signal before its node's first message.

The exported ``ros_short`` (its distance monitor a C++ node) launched with ``mode:=free``:
the run's ``min_distance`` is the in-process run's within the free-mode tolerance, never the
0.0 the simulator's buffer held while the nodes were starting. Skipped, with the reason,
where ROS, catkin, unshare or root is missing.
"""

from __future__ import annotations

import json
import os
import subprocess
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
import yaml
from ros_launch import Launch, ros_missing

import amsa_phys as ap

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "ros_short.yaml"
SIGNAL = "MyDistanceMonitor.distanceFollowerToLeader"
EDIT = "/Leader/circleRadius"

pytestmark = pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing()))
launcher = ros_launch.launcher  # the fixture


def test_free_mode_min_distance_is_a_measured_one(
    ros_short_workspace: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    out = tmp_path / "free"
    launch = launcher(
        ros_short_workspace,
        "ros_short.launch",
        f"out:={out}",
        "plots:=false",
        "mode:=free",
        "speed:=4",
    )
    # an edit made while the run starts (circleRadius: unused by a straight-driving leader)
    # is never lost: it is the run's start value if it landed before the run read the
    # server, a live change at the first instant if after; it used to be lost when it
    # landed between that read and the one the free mode's edit watch started from
    # roslaunch loads the parameters after its core service, then starts the nodes
    for line in ("started core service", "started with pid"):
        assert launch.read_until(line), "".join(launch.lines)[-3000:]
    edit = subprocess.run(
        ["nsenter", "-t", str(launch.proc.pid), "-n", "rosparam", "set", EDIT, "7.5"],
        capture_output=True,
        text=True,
        env={**os.environ, "ROS_MASTER_URI": "http://localhost:11311"},
    )
    assert edit.returncode == 0, edit.stderr
    text = launch.finish()
    assert "completed" in text, text[-3000:]
    start = yaml.safe_load((out / "scenario.yaml").read_text()).get("set") or {}
    events = [e["detail"] for e in json.loads((out / "metrics.json").read_text())["events"]]
    taken = [start.get("Leader.circleRadius") == 7.5, "Leader.circleRadius=7.5" in events]
    assert taken.count(True) == 1, (start, events)
    free = json.loads((out / "metrics.json").read_text())["overall"]
    assert free["min_distance"] > 1.0, free  # no 0.0 from before the monitor's first message
    # the in-process run's distances once its monitor has stepped (its timer phase is
    # 0.125 s: before it, its trace holds the port's initial 0.0 too)
    trace = ap.run(str(SCENARIO)).trace
    measured = trace[SIGNAL][trace["t"] >= 0.125]
    assert abs(free["min_distance"] - measured.min()) < 1.0, (free, measured.min())
