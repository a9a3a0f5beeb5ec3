"""Free mode counts no sample of the quality signal before its node's first message.

The exported ``ros_short`` (its distance monitor a C++ node) launched with ``mode:=free``:
the run's ``min_distance`` is the in-process run's within the free-mode tolerance, never the
0.0 the simulator's buffer held while the nodes were starting. Skipped, with the reason,
where ROS, catkin, unshare or root is missing.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, ros_missing

import amsa_phys as ap

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "ros_short.yaml"
SIGNAL = "MyDistanceMonitor.distanceFollowerToLeader"

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
    text = launch.finish()
    assert "completed" in text, text[-3000:]
    free = json.loads((out / "metrics.json").read_text())["overall"]
    assert free["min_distance"] > 1.0, free  # no 0.0 from before the monitor's first message
    # the in-process run's distances once its monitor has stepped (its timer phase is
    # 0.125 s: before it, its trace holds the port's initial 0.0 too)
    trace = ap.run(str(SCENARIO)).trace
    measured = trace[SIGNAL][trace["t"] >= 0.125]
    assert abs(free["min_distance"] - measured.min()) < 1.0, (free, measured.min())
