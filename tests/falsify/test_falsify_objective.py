"""What falsify minimises: a metric's negative, or the robustness of the expect checks,
with the verdicts of ``amsa-phys test`` (runs.expect) on the same numbers."""

from __future__ import annotations

import math
import re

import pytest

from amsa_phys.errors import ConfigError
from amsa_phys.falsify.objective import build_objective, margin, row_metrics
from amsa_phys.model.scenario import Expectation


def expect(metric: str | None, phase: int | None = None, below=None, above=None, trace=None):
    return Expectation(metric, phase, below, above, None, trace)


def row(**metrics: float | None) -> dict:
    out = {"run": 0, "error": "", "rms_error": 1.0, "max_distance": 20.0, "settling_time": 5.0}
    out.update({"phase0.rms_error": 1.0, "phase0.max_distance": 20.0})
    out.update(metrics)
    return out


def test_margin_is_signed_distance_to_the_nearest_bound() -> None:
    assert margin(expect("m", below=26), 24.5) == 1.5
    assert margin(expect("m", below=26), 27.0) == -1.0
    assert margin(expect("m", above=2), 1.5) == -0.5
    assert margin(expect("m", below=10, above=2), 9.0) == 1.0  # nearer the upper bound
    assert margin(expect("m", below=10, above=2), 2.5) == 0.5
    assert margin(expect("m", below=10), None) == -math.inf  # never settled: fails


def test_robustness_is_the_least_margin_and_agrees_with_test() -> None:
    checks = [expect("rms_error", below=1.2), expect("max_distance", phase=0, below=21)]
    objective, warnings = build_objective(checks, None, True, 1)
    assert warnings == []
    v = objective.judge(row())
    assert v.value == pytest.approx(0.2)  # rms 1.0 vs 1.2: the nearer bound
    assert not v.violated
    v = objective.judge(row(**{"phase0.max_distance": 22.5}))
    assert v.value == pytest.approx(-1.5)
    assert v.violated
    assert v.why == "max_distance (phase 0) = 22.5, below 21: FAIL"
    # a margin of exactly 0 fails, as in `amsa-phys test` (its bounds are strict)
    v = objective.judge(row(rms_error=1.2))
    assert v.value == 0.0
    assert v.violated


def test_a_fault_is_the_worst_and_an_unrunnable_point_the_least_interesting() -> None:
    objective, _ = build_objective([expect("rms_error", below=1.2)], None, True, 1)
    fault = objective.judge(row(error="run fault at t=3.000 s in Follower: boom"))
    assert fault.score == -math.inf
    assert fault.violated
    assert fault.why.startswith("run fault at t=3.000 s in Follower: boom")
    refused = objective.judge({"run": 1, "error": "a rule broken", "seed": 1})
    assert refused.score == math.inf
    assert not refused.violated


def test_metric_mode_maximises_and_judges_only_that_metrics_checks() -> None:
    checks = [expect("rms_error", below=1.2), expect("max_distance", below=19)]
    objective, _ = build_objective(checks, "rms_error", False, 1)
    assert objective.checks == (checks[0],)
    v = objective.judge(row(rms_error=1.1))  # max_distance 20 breaks its bound: not ours
    assert (v.value, v.score, v.violated) == (1.1, -1.1, False)
    assert objective.judge(row(rms_error=1.3)).violated
    phase, _ = build_objective(
        [expect("rms_error", phase=0, below=0.5), *checks], "phase0.rms_error", False, 1
    )
    assert [(e.metric, e.phase) for e in phase.checks] == [("rms_error", 0)]
    settling, _ = build_objective([], "settling_time", False, 1)
    assert settling.judge(row(settling_time=None)).score == -math.inf  # never settled


def test_expect_without_metric_checks_is_refused_and_trace_checks_are_said() -> None:
    trace = expect(None, trace="MyDistanceMonitor.distanceFollowerToLeader", below=30)
    message = "--expect: the scenario has no expect: check on a metric to falsify; give --metric M"
    with pytest.raises(ConfigError, match=f"^{re.escape(message)}$"):
        build_objective([trace], None, True, 1)
    objective, warnings = build_objective(
        [trace, expect("rms_error", below=2), expect("rms_error", phase=3, below=2)],
        None,
        True,
        2,
    )
    assert len(objective.checks) == 1
    assert warnings == [
        "the expect check on MyDistanceMonitor.distanceFollowerToLeader in [0, end] s is a "
        "trace check: falsify judges metric checks only (the search keeps no traces); it is "
        "left out",
        "the expect check rms_error (phase 3), below 2 is on a phase the runs never reach; it "
        "is left out",
    ]


def test_row_metrics_rebuilds_phases() -> None:
    doc = row_metrics({"rms_error": 1.0, "phase0.rms_error": 2.0, "phase1.max_distance": 3.0})
    assert doc["overall"]["rms_error"] == 1.0
    assert doc["phases"] == [{"rms_error": 2.0}, {"max_distance": 3.0}]
