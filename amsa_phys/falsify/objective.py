"""What a falsification minimises: a metric's negative, or the robustness of ``expect``.

Robustness (as in S-TaLiRo and Breach) is the signed margin by which a run meets its
requirements: for each ``expect`` check on a metric, ``below - value`` and ``value - above``,
negative when the bound is broken; the least over every check. Pass and fail come from
``runs.expect.check_expectations`` itself, so ``falsify --expect`` and ``amsa-phys test``
never disagree on a verdict (a margin of exactly 0 fails there: the bounds are strict).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from ..errors import ConfigError
from ..model.scenario import METRICS, Expectation
from ..runs.expect import check_expectations, describe_bound, describe_what

_PHASE = re.compile(r"phase(\d+)\.(.+)")


@dataclass(frozen=True)
class Verdict:
    """One run judged: ``value`` is what the user reads (the metric, or the robustness),
    ``score`` what the optimizer minimises (``-inf``: a fault or a metric never reached,
    the worst there is; ``+inf``: a point whose settings no run could take)."""

    value: float | None
    score: float
    violated: bool
    why: str = ""


def row_metrics(row: dict[str, Any]) -> dict[str, Any]:
    """A result row's metric columns back as a ``metrics.json``-shaped document."""
    phases: list[dict[str, Any]] = []
    for key, value in row.items():
        m = _PHASE.fullmatch(key)
        if m is not None:
            i = int(m.group(1))
            while len(phases) <= i:
                phases.append({})
            phases[i][m.group(2)] = value
    return {"overall": {k: row.get(k) for k in METRICS}, "phases": phases}


def _has_metrics(row: dict[str, Any]) -> bool:
    return any(k in row for k in METRICS)


@dataclass(frozen=True)
class Objective:
    """``metric`` (maximised; its ``expect`` checks decide a violation) or, with ``metric``
    None, the robustness of ``checks`` (minimised; below 0 is a violation)."""

    metric: str | None
    checks: tuple[Expectation, ...]

    @property
    def label(self) -> str:
        """What the value column and the plot's axis are called."""
        return self.metric or "robustness"

    def judge(self, row: dict[str, Any]) -> Verdict:
        """The verdict on one result row."""
        if not _has_metrics(row):  # its settings broke a rule before it ran
            return Verdict(None, math.inf, False, row.get("error", ""))
        fault = row.get("error", "")
        checks = check_expectations(list(self.checks), row_metrics(row))
        failed = [c for c in checks if not c.skipped and not c.passed]
        why = "; ".join(c.describe() for c in failed)
        if fault:
            why = fault + (f"; {why}" if why else "")
        if self.metric is not None:
            value = row.get(self.metric)
            score = -math.inf if fault or value is None else -float(value)
            return Verdict(value, score, bool(fault or failed), why)
        margins = [margin(c.expectation, c.value) for c in checks if not c.skipped]
        value = min(margins) if margins else math.inf
        if fault:
            value = -math.inf
        return Verdict(value, value, bool(fault or failed), why)


def margin(e: Expectation, value: float | None) -> float:
    """Signed distance of ``value`` to the bounds of ``e`` (negative: a bound broken;
    ``-inf``: no value, which fails every bound)."""
    if value is None:
        return -math.inf
    out = math.inf
    if e.below is not None:
        out = min(out, e.below - value)
    if e.above is not None:
        out = min(out, value - e.above)
    return out


def _check_metric(e: Expectation) -> str:
    return f"phase{e.phase}.{e.metric}" if e.phase is not None else str(e.metric)


def build_objective(
    expect: list[Expectation], metric: str | None, use_expect: bool, n_phases: int
) -> tuple[Objective, list[str]]:
    """The objective of ``--metric M`` or ``--expect``, and warnings to print once.

    ``--expect`` judges the scenario's checks on metrics; a trace check needs the run's
    trace, which a search does not keep, so it is left out, said once. A check on a phase
    the (possibly shortened) run never reaches is left out too.
    """
    warnings = []
    usable = []
    for e in expect:
        if e.trace is not None:
            if use_expect:
                warnings.append(
                    f"the expect check on {describe_what(e)} is a trace check: falsify judges "
                    "metric checks only (the search keeps no traces); it is left out"
                )
            continue
        if e.phase is not None and e.phase >= n_phases:
            if use_expect:
                warnings.append(
                    f"the expect check {describe_what(e)}, {describe_bound(e)} is on a phase "
                    "the runs never reach; it is left out"
                )
            continue
        usable.append(e)
    if use_expect:
        if not usable:
            raise ConfigError(
                "the scenario has no expect: check on a metric to falsify; give --metric M",
                key="--expect",
            )
        return Objective(None, tuple(usable)), warnings
    name = metric or "rms_error"
    return Objective(name, tuple(e for e in usable if _check_metric(e) == name)), warnings
