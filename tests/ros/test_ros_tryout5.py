"""Pipelined lockstep through ``rosrun PKG run_lockstep``, as a CI runs it: the exit code.

``run_lockstep``'s verdict on a run directory is unit-tested (tests/ros/test_ros_runcheck.py)
and a pipelined divergence's fault by roslaunch (tests/ros/test_ros_nodes.py); here the script
itself drives a pipelined run of one small build (``tests/fixtures/ros_short.yaml``, every
remote Leaf in the C++ container): Ctrl-C in the middle exits 130 with the outputs kept and no
process left, and a node that does not do what the model's template does (the launch file's
``/amsa/seed`` edited by hand, so the C++ sensors draw other noise) exits 2 with one line naming
the Leaf and the way out, ``pipeline:=false``. Skipped, with the reason, where ROS, catkin,
unshare or root is missing.
"""

from __future__ import annotations

import json
import os
import re
import signal
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, package_edit, ros_missing

ROOT = Path(__file__).resolve().parent.parent.parent
PKG = "mdeChallenge"

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture
# ros_short_workspace, ros_short_checked: the session's build of ros_short and its
# run_lockstep (tests/ros/conftest.py), edited only through ``package_edit``


def test_ctrl_c_in_a_pipelined_run_is_130_with_the_outputs_kept(
    ros_short_checked: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    """Ctrl-C (SIGINT to the process group, as a terminal sends it) once the scenario node
    has applied its first change: the run is pipelined, the script exits 130 and says so,
    the run directory says ``interrupted``, and no process of the launch is left."""
    out = tmp_path / "interrupted"
    launch = launcher(
        ros_short_checked, "ros_short.launch", f"out:={out}", "plots:=false", "duration:=36000"
    )
    lines = launch.lines
    assert launch.read_until("running ros_short (lockstep, pipelined)"), "".join(lines)[-3000:]
    assert launch.read_until("phase 1 at t=10 s"), "".join(lines)[-3000:]
    os.killpg(launch.proc.pid, signal.SIGINT)
    text = launch.finish()  # fails if any process of the launch is left
    assert launch.proc.returncode == 130, text[-3000:]
    assert f"run_lockstep: the run was interrupted; outputs so far in {out}" in text
    assert json.loads((out / "metrics.json").read_text())["status"] == "interrupted"
    assert len((out / "trace.csv").read_text().splitlines()) > 10 * 20  # 10 s at 20 Hz


def test_a_node_unlike_its_template_is_2_and_the_fault_names_the_way_out(
    ros_short_workspace: Path,
    ros_short_checked: Path,
    launcher: Callable[..., Launch],
    tmp_path: Path,
) -> None:
    """The launch file's ``/amsa/seed`` edited by hand: a C++ sensor draws other noise than
    the model's template, the pipelined run stops at that step and the script exits 2 with
    the fault in one line: the Leaf, its node, both values and ``pipeline:=false``."""
    launch_dir = ros_short_workspace / "src" / PKG / "launch"
    original = (launch_dir / "ros_short.launch").read_text()
    seed = re.search(r'<param name="seed" type="str" value="(\d+)"/>', original)
    assert seed is not None, original[:2000]
    reseeded = seed.group(0).replace(f'"{seed.group(1)}"', f'"{int(seed.group(1)) + 1}"')
    with package_edit(launch_dir / "reseeded.launch", original.replace(seed.group(0), reseeded)):
        out = tmp_path / "reseeded"
        launch = launcher(ros_short_checked, "reseeded.launch", f"out:={out}", "plots:=false")
        text = launch.finish()
    assert launch.proc.returncode == 2, text[-3000:]
    assert "running ros_short (lockstep, pipelined)" in text
    verdict = [ln for ln in text.splitlines() if ln.startswith("run_lockstep: ")]
    assert len(verdict) == 1, text[-3000:]
    assert re.match(
        r"run_lockstep: the run did not complete \(fault: run fault at t=\S+ s in "
        r"(\w+) \((?:GPS|Compass)\): its node /\1 published .* "
        r"where its in-process template published .*"
        r"run with pipeline:=false to follow the node\)\); outputs in ",
        verdict[0],
    ), verdict[0]
