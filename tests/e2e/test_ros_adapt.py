"""``adapt:`` rules in the exported package (issue 27 item 5).

The adaptive scenario (``scenarios/adaptive.yaml``: context estimators, rules switching the
controller's Kv) is exported, built and launched in lockstep for its first 70 s, in which
two rules fire (t = 40.1 s and 57.1 s in-process): the run equals ``amsa-phys run --duration
70`` byte for byte (trace.csv, with the rule column, and metrics.json with its adapt events).
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
SCENARIO = ROOT / "scenarios" / "adaptive.yaml"
PKG = "mdeAdaptive"  # the world's name

pytestmark = pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing()))
launcher = ros_launch.launcher  # the fixture


_metrics = ros_launch.metrics_without_wall


def test_lockstep_fires_the_rules_where_amsa_phys_run_does(
    tmp_path_factory: pytest.TempPathFactory, launcher: Callable[..., ros_launch.Launch]
) -> None:
    ref = tmp_path_factory.mktemp("ref") / "run"
    args = ["--headless", "-q", "--no-plot", "--duration", "70", "--out", str(ref)]
    assert main(["run", str(SCENARIO), *args]) == 0
    fired = [
        e for e in json.loads((ref / "metrics.json").read_text())["events"] if e["kind"] == "adapt"
    ]
    assert len(fired) >= 2  # the test would prove nothing without firings
    ws = build_workspace(tmp_path_factory.mktemp("adapt_ws"), SCENARIO, PKG)
    out = ws / "lockstep"
    text = launcher(ws, "adaptive.launch", f"out:={out}", "plots:=false", "duration:=70").finish()
    assert "completed" in text or "partial" in text, text[-3000:]
    assert (out / "trace.csv").read_bytes() == (ref / "trace.csv").read_bytes()
    assert _metrics(out) == _metrics(ref)
