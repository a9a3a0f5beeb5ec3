"""Array ports in ``export ros``: the obstacle course (a lidar and a ReactiveAvoider), lockstep.

``scenarios/obstacle_course.yaml`` (issue 16's worked example) is exported, built with catkin
and launched in lockstep for its first 12 s: the lidar's 31 ranges travel from the simulator
(where the Lidar casts its rays into the pymunk world) to the ReactiveAvoider's node as one
``std_msgs/Float64MultiArray`` topic, ``/Scanner/ranges``. The trace and metrics must equal
``amsa-phys run --duration 12`` byte for byte with the C++ ReactiveAvoider (the default) and
with its Python twin (``cpp:=false``). Mutation-checked: the C++ body's beam directions
computed as ``k * delta / div + lo`` instead of numpy's ``k * step + lo`` (last-bit
differences) fails the C++ case (``tests/unit/test_cpp_avoider.py`` compares the body with
the template bit for bit on random scans, where rarer differences show). Skipped, with the reason, where ROS, catkin, unshare or root is missing.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, build_workspace, ros_missing

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "scenarios" / "obstacle_course.yaml"
PKG = "obstacleCourse"  # the world's name
DURATION = "12"  # s: past the first obstacle (the avoider turns), a few seconds of launch

pytestmark = pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing()))
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


def test_the_avoider_is_a_cpp_node_reading_one_array_topic(workspace: Path) -> None:
    src = workspace / "src" / PKG
    assert (workspace / "devel" / "lib" / PKG / "Pilot_cpp").is_file()
    node = (src / "src" / "Pilot.cpp").read_text()
    assert '{"/Scanner/ranges", 0.0, false, 31}' in node  # an array topic of 31 values
    assert "/Scanner/ranges [31]" in (src / "nodes" / "Pilot.py").read_text()


@pytest.mark.parametrize("cpp", ["true", "false"])
def test_lockstep_reproduces_the_obstacle_course_with_cpp_and_python_avoider(
    workspace: Path, reference: Path, launcher: Callable[..., Launch], cpp: str
) -> None:
    out = workspace / f"lockstep_cpp_{cpp}"
    args = [f"out:={out}", "plots:=false", f"cpp:={cpp}", f"duration:={DURATION}"]
    text = launcher(workspace, "obstacle_course.launch", *args).finish()
    assert "partial" in text or "completed" in text, text[-3000:]
    assert (out / "trace.csv").read_bytes() == (reference / "trace.csv").read_bytes()
    assert ros_launch.metrics_without_wall(out) == ros_launch.metrics_without_wall(reference)
