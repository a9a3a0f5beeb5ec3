"""The C++ nodes of every shipped template that has one, in lockstep, against ``amsa-phys run``.

``tests/fixtures/ros_nodes.yaml`` runs every template with a C++ body (``ros/files/cpp/``):
the MDE loop (GPS, Compass, DistanceMonitor, FollowerController, NormalizePower), the
context estimators (GPSLossMonitor on a lossy leader GPS, MotorMonitor on worn motors,
LeaderMonitor on a turning leader), and an open-loop cart (ConstantPower) whose GPS,
compass, IMU (with the pose and a lever arm) and wheel odometry use every noise term
(turn-on bias, random-walk and Gauss-Markov biases, latency, bursts and losses,
quantisation), with a GpsDistance on its fix and a GoalMonitor whose inputs are written in
another order than the template's, and a scout steered round a post by a ReactiveAvoider
reading its lidar (an array input); the timeline changes parameters of the new nodes inside
the run. Lockstep must reproduce the in-process run byte for byte with the C++ nodes (the
default) and with their Python twins (``cpp:=false``). Mutation-checked, each mutation
changing its own columns of the trace: a flipped turn-on sign in the GPS and in the compass,
a MotorMonitor edge window keeping its first segment, LeaderMonitor taking its fixes 1 ns
late, GPSLossMonitor's window judged full 2 ns late, the IMU's lever arm with the wrong
sign, the odometry's chord along the old heading, ConstantPower's left power from
``right``, GoalMonitor's x from ``goalY``. Skipped, with the reason, where ROS, catkin,
unshare or root is missing. (catkin_make of its 17 C++ nodes takes minutes on a loaded
machine: each is an executable of its own compiled against roscpp's headers.)
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, build_workspace, ros_missing

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros import names
from amsa_phys.ros.cppnode import cpp_bodies, has_cpp

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "ros_nodes.yaml"
PKG = "rosNodes"

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The exported package, built with catkin in a fresh workspace."""
    return build_workspace(tmp_path_factory.mktemp("ws"), SCENARIO, PKG)


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``amsa-phys run`` of the same scenario, in-process."""
    out = tmp_path_factory.mktemp("ref") / "run"
    assert main(["run", str(SCENARIO), "--headless", "--out", str(out), "-q", "--no-plot"]) == 0
    return out


_metrics = ros_launch.metrics_without_wall


def test_the_fixture_runs_every_cpp_template_as_a_cpp_node(workspace: Path) -> None:
    world = load_scenario(SCENARIO).world
    bodies = cpp_bodies()
    ran = {leaf.template.name() for leaf in world.leaves.values() if has_cpp(leaf, bodies)}
    # the scout's ReactiveAvoider reads its lidar (an array port, inline in pipelined
    # requests); test_ros_arrays.py runs the obstacle course too (not pipelined: its IMU is
    # a Python node)
    assert ran == {t.name() for t in bodies}
    # one nodelet class per template, compiled once into the package's library, and the
    # container that loads every C++ Leaf of the package into one process
    assert (workspace / "devel" / "lib" / f"lib{PKG}_leaves.so").is_file()
    assert (workspace / "devel" / "lib" / PKG / names.CONTAINER).is_file()
    sources = sorted(p.stem for p in (workspace / "src" / PKG / "src" / "leaves").iterdir())
    assert sources == sorted(ran)


@pytest.mark.parametrize(
    "args",
    [
        (),  # the default: every C++ Leaf in one process (amsa_leaves), pipelined
        ("pipeline:=false",),  # ... each instant's answers awaited, the nodes' values used
        ("cpp_container:=false",),  # each C++ Leaf in a process of its own
        ("cpp:=false",),  # the Python twins
    ],
    ids=["container", "container_exact", "standalone", "python"],
)
def test_lockstep_reproduces_the_run_with_cpp_nodes_and_without(
    workspace: Path, reference: Path, launcher: Callable[..., Launch], args: tuple[str, ...]
) -> None:
    out = workspace / ("lockstep_" + ("_".join(args).replace(":=", "_") or "container"))
    launch = launcher(workspace, "ros_nodes.launch", f"out:={out}", "plots:=false", *args)
    text = launch.finish()
    assert "completed" in text, text[-3000:]
    if not args or args == ("pipeline:=false",):  # one process hosts every C++ Leaf
        assert text.count("process[amsa_leaves") == 1, text[-3000:]
        assert "(nodelet/nodelet)" not in text, text[-3000:]
    # pipelined by default (every remote Leaf is in the container); else each instant awaited
    assert ("(lockstep, pipelined)" in text) == (not args), text[-3000:]
    assert (out / "trace.csv").read_bytes() == (reference / "trace.csv").read_bytes()
    assert _metrics(out) == _metrics(reference)


def test_a_node_unlike_its_template_stops_a_pipelined_run_and_drives_an_exact_one(
    workspace: Path, reference: Path, launcher: Callable[..., Launch]
) -> None:
    """The launch file's ``/amsa/seed`` edited by hand: the C++ sensors draw other noise than
    the model's. Pipelined lockstep ends at the first step where a node published another
    value than its in-process template, naming both; the exact protocol (``pipeline:=false``)
    follows the nodes, so its run completes and differs from ``amsa-phys run``."""
    launch_dir = workspace / "src" / PKG / "launch"
    original = (launch_dir / "ros_nodes.launch").read_text()
    seed = re.search(r'<param name="seed" type="str" value="(\d+)"/>', original)
    assert seed is not None, original[:2000]
    reseeded = seed.group(0).replace(f'"{seed.group(1)}"', f'"{int(seed.group(1)) + 1}"')
    (launch_dir / "ros_nodes_reseeded.launch").write_text(original.replace(seed.group(0), reseeded))
    try:
        out = workspace / "reseeded"
        text = launcher(
            workspace, "ros_nodes_reseeded.launch", f"out:={out}", "plots:=false"
        ).finish()
        assert "where its in-process template published" in text, text[-3000:]
        status = json.loads((out / "metrics.json").read_text())["status"]
        assert re.match(
            r"fault: run fault at t=\S+ s in \w+ \((GPS|Compass|IMU|Odometry)\)", status
        )
        exact = workspace / "reseeded_exact"
        text = launcher(
            workspace,
            "ros_nodes_reseeded.launch",
            f"out:={exact}",
            "plots:=false",
            "pipeline:=false",
        ).finish()
        assert "completed" in text, text[-3000:]
        assert (exact / "trace.csv").read_bytes() != (reference / "trace.csv").read_bytes()
    finally:
        (launch_dir / "ros_nodes_reseeded.launch").unlink()
