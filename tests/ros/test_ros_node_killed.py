"""Killing the ``amsa_leaves`` container mid-run: ``rosrun PKG run_lockstep`` exits 2 naming
the node, not 130 "interrupted" (roslaunch's shutdown after a required node died looks like
a Ctrl-C to the simulator; the launch's own words say which it was).

Runs in ``unshare -n`` on the session's build of ``tests/fixtures/ros_short.yaml``; skipped,
with the reason, where ROS, catkin, unshare or root is missing.
"""

from __future__ import annotations

import os
import signal
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, ros_missing

pytestmark = pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing()))
launcher = ros_launch.launcher  # the fixture
STARTED = "nodes connected, running"


def _pids_of(launch: Launch, name: str) -> list[int]:
    """The launch's processes whose command line names ``name``."""
    out = []
    for pid in ros_launch._leftovers(launch.token):
        try:
            cmdline = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if any(Path(part.decode(errors="replace")).name == name for part in cmdline[:2]):
            out.append(pid)
    return out


def test_a_killed_container_is_exit_2_naming_it(
    ros_short_checked: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    out = tmp_path / "killed"
    launch = launcher(ros_short_checked, "ros_short.launch", f"out:={out}", "plots:=false")
    assert launch.read_until(STARTED), "".join(launch.lines)[-3000:]
    pids = _pids_of(launch, "amsa_leaves")
    assert len(pids) == 1, pids
    os.kill(pids[0], signal.SIGKILL)
    text = launch.finish()
    assert launch.proc.returncode == 2, text[-3000:]
    last = text.strip().splitlines()[-1]
    assert last.startswith("run_lockstep: node amsa_leaves died mid-run"), text[-3000:]
    assert f"outputs so far in {out}" in last
    assert (out / "trace.csv").is_file()
