"""A ROS 1 lockstep run judges a scenario's STL requirements as ``amsa-phys run`` does.

The simulator node builds its own Simulation (``runtime/rossim.py``); one that does not sample
what the requirements read writes a ``metrics.json`` without them, and ``run_lockstep`` then
fails every requirement as "not judged". The session's package (tests/ros/conftest.py) gets
one requirement in its resolved scenario, edited in place and put back afterwards.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, package_edit, ros_missing

from amsa_phys.cli.main import main

PKG = "mdeChallenge"
REQUIREMENT = (
    '- {stl: "always(MyDistanceMonitor.distanceFollowerToLeader <= 40)", name: keeps_up}\n'
)

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture


def test_lockstep_judges_the_stl_requirements_as_the_in_process_run(
    ros_short_workspace: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    config = ros_short_workspace / "src" / PKG / "config" / "ros_short.yaml"
    original = config.read_text()
    assert "\nexpect:\n" in original
    edited = original.replace("\nexpect:\n", "\nexpect:\n" + REQUIREMENT, 1)
    (tmp_path / "scenario.yaml").write_text(edited)
    ref = tmp_path / "ref"
    argv = ["run", str(tmp_path / "scenario.yaml"), "--headless", "--no-plot", "-q"]
    assert main([*argv, "--out", str(ref)]) == 0
    expected = json.loads((ref / "metrics.json").read_text())["requirements"]
    assert expected["keeps_up"]["robustness"] > 0
    checked = ros_launch.run_lockstep_dir(ros_short_workspace, PKG, tmp_path / "checked")
    out = checked / "lock"
    with package_edit(config, edited):
        run = launcher(checked, "ros_short.launch", f"out:={out}", "plots:=false")
        text = run.finish()
    assert run.proc.returncode == 0, text[-3000:]
    assert "requirement keeps_up" in text
    assert json.loads((out / "metrics.json").read_text())["requirements"] == expected
