"""``adapt:`` rules in the exported package (issue 27 item 5).

The adaptive world and its shipped rules (``tests/fixtures/ros_adaptive.yaml``: context
estimators, rules switching the controller's Kv; worn motors from the start, very worn at
45 s) are exported, built and launched in lockstep for 75 s, in which three rules fire
(t = 10, 42.1 and 72.1 s in-process): the run equals ``amsa-phys run`` byte for byte
(trace.csv, with the rule column, and metrics.json with its adapt events and switch count),
with the rules fired inside the simulator (``rules:=sim``, the default) and by the
``amsa_adapt`` node, the one a robot runs with ``sim:=false`` (``rules:=node``: the
simulator asks it at every instant; ``ros/runtime/adaptlink.py``). Mutation-checked: the
adapt node judging each signal's previous message instead of the one the simulator names
fires a rule one step late and the ``rules:=node`` case fails.
Skipped, with the reason, where ROS is missing.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import build_workspace, ros_missing

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "ros_adaptive.yaml"
PKG = "mdeAdaptive"  # the world's name

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture


_metrics = ros_launch.metrics_without_wall


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``amsa-phys run``, in-process: the rules fire at least twice."""
    ref = tmp_path_factory.mktemp("ref") / "run"
    args = ["--headless", "-q", "--no-plot", "--out", str(ref)]
    assert main(["run", str(SCENARIO), *args]) == 0
    fired = [
        e for e in json.loads((ref / "metrics.json").read_text())["events"] if e["kind"] == "adapt"
    ]
    assert len(fired) >= 2  # the test would prove nothing without firings
    return ref


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The adaptive scenario exported and built (shared by both launches)."""
    return build_workspace(tmp_path_factory.mktemp("adapt_ws"), SCENARIO, PKG)


@pytest.mark.parametrize("rules", ["sim", "node"])
def test_lockstep_fires_the_rules_where_amsa_phys_run_does(
    workspace: Path, reference: Path, launcher: Callable[..., ros_launch.Launch], rules: str
) -> None:
    """``rules:=sim``: the simulator fires them; ``rules:=node``: the ``amsa_adapt`` node
    (the one a robot runs with ``sim:=false``) decides, asked at every instant."""
    out = workspace / f"lockstep_{rules}"
    args = [f"out:={out}", "plots:=false", f"rules:={rules}"]
    text = launcher(workspace, "ros_adaptive.launch", *args).finish()
    assert "completed" in text or "partial" in text, text[-3000:]
    assert (f"amsa_adapt ({PKG}/amsa_adapt.py)" in text) == (rules == "node")
    assert (out / "trace.csv").read_bytes() == (reference / "trace.csv").read_bytes()
    assert _metrics(out) == _metrics(reference)
