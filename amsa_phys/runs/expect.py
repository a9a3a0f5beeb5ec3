"""Checking a run's metrics against the scenario's ``expect`` entries."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..model.scenario import Expectation


@dataclass
class Check:
    """One expectation and what was measured."""

    expectation: Expectation
    value: float | None
    passed: bool
    skipped: bool = False

    def describe(self) -> str:
        """``max_distance (phase 1) = 24.3, below 26: pass``."""
        e = self.expectation
        where = f" (phase {e.phase})" if e.phase is not None else ""
        bounds = []
        if e.below is not None:
            bounds.append(f"below {e.below:g}")
        if e.above is not None:
            bounds.append(f"above {e.above:g}")
        if self.skipped:
            return f"{e.metric}{where}: skipped (phase not run, --duration cut it)"
        value = "none" if self.value is None else f"{self.value:.4g}"
        verdict = "pass" if self.passed else "FAIL"
        return f"{e.metric}{where} = {value}, {' and '.join(bounds)}: {verdict}"


def check_expectations(expect: list[Expectation], metrics: dict[str, Any]) -> list[Check]:
    """Evaluate every expectation; a metric that is null (never settled) fails a bound."""
    checks = []
    for e in expect:
        if e.phase is not None and e.phase >= len(metrics["phases"]):
            checks.append(Check(e, None, True, skipped=True))
            continue
        block = metrics["overall"] if e.phase is None else metrics["phases"][e.phase]
        value = block.get(e.metric)
        ok = value is not None
        if ok and e.below is not None:
            ok = value < e.below
        if ok and e.above is not None:
            ok = value > e.above
        checks.append(Check(e, value, ok))
    return checks
