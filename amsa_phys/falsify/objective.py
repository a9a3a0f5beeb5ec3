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
from ..requirements.objective import column, objective_value, requirement_of, unknown_objective
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
    """A result row's metric columns back as a ``metrics.json``-shaped document (with each
    ``robustness.NAME`` as its requirement's entry)."""
    phases: list[dict[str, Any]] = []
    reqs: dict[str, Any] = {}
    for key, value in row.items():
        m = _PHASE.fullmatch(key)
        if m is not None:
            i = int(m.group(1))
            while len(phases) <= i:
                phases.append({})
            phases[i][m.group(2)] = value
        name = requirement_of(key)
        if name is not None:
            if value is None:  # the run could not judge it (its windows cut by the run's end)
                reqs[name] = {"robustness": None, "verdict": "skipped", "note": SKIPPED}
                continue
            ok = value >= 0
            reqs[name] = {"robustness": value, "verdict": "pass" if ok else "fail"}
    # a row says which requirements its run judged (an empty column: not judged), so the
    # run's length, which a row does not hold, is not needed to tell: none is cut by it here
    out = {"overall": {k: row.get(k) for k in METRICS}, "phases": phases, "simulated": math.inf}
    if reqs:
        out["requirements"] = reqs
    return out


#: why a requirement whose robustness column is empty was not judged
SKIPPED = "the run could not judge it (its windows reach past the run's end)"


def has_metrics(row: dict[str, Any]) -> bool:
    return any(k in row for k in METRICS)


@dataclass(frozen=True)
class Objective:
    """``metric`` (maximised; its ``expect`` checks decide a violation) or, with ``metric``
    None, the robustness of ``checks`` (minimised; below 0 is a violation)."""

    metric: str | None
    checks: tuple[Expectation, ...]
    #: STL requirements whose least robustness is minimised (``--requirement``); a run
    #: falsifies when it is below 0
    requirements: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        """What the value column and the plot's axis are called."""
        if len(self.requirements) == 1:
            return column(self.requirements[0])
        return self.metric or "robustness"

    @property
    def falsifies(self) -> bool:
        """Whether this objective is a requirement's robustness (stop at the first < 0)."""
        return bool(self.requirements)

    def judge(self, row: dict[str, Any]) -> Verdict:
        """The verdict on one result row."""
        if not has_metrics(row):  # its settings broke a rule before it ran
            return Verdict(None, math.inf, False, row.get("error", ""))
        fault = row.get("error", "")
        if self.requirements:
            return self._judge_requirements(row, fault)
        checks = check_expectations(list(self.checks), row_metrics(row))
        failed = [c for c in checks if not c.skipped and not c.passed]
        why = "; ".join(c.describe() for c in failed)
        if fault:
            why = fault + (f"; {why}" if why else "")
        if self.metric is not None:
            value = row.get(self.metric)
            score = -math.inf if fault or value is None else -float(value)
            return Verdict(value, score, bool(fault or failed), why)
        margins = [
            (c.value if c.value is not None else -math.inf)
            if c.expectation.stl is not None
            else margin(c.expectation, c.value)
            for c in checks
            if not c.skipped
        ]
        value = min(margins) if margins else math.inf
        if fault:
            value = -math.inf
        return Verdict(value, value, bool(fault or failed), why)

    def _judge_requirements(self, row: dict[str, Any], fault: str) -> Verdict:
        """The least robustness of the requirements (a fault, or a robustness that is not a
        finite number, is the worst there is: -inf)."""
        values = []
        for name in self.requirements:
            value, _ = objective_value(row, column(name))
            values.append((-math.inf if value is None else value, name))
        value, name = min(values) if not fault else (-math.inf, self.requirements[0])
        violated = value < 0
        why = fault or (f"requirement {name}: robustness {value:.6g}" if violated else "")
        return Verdict(value, value, violated, why)


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
        if e.stl is not None:
            usable.append(e)  # judged from its robustness.NAME column
            continue
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
    if requirement_of(name) is not None:
        return requirement_objective(expect, requirement_of(name) or "", "--metric"), warnings
    return Objective(
        name, tuple(e for e in usable if e.stl is None and _check_metric(e) == name)
    ), warnings


def requirement_objective(expect: list[Expectation], name: str, option: str) -> Objective:
    """The objective of ``--requirement NAME`` (``all``: the least robustness of every STL
    requirement of the scenario), judged before any run."""
    names = [str(e.name) for e in expect if e.stl is not None]
    if not names:
        raise ConfigError(
            "the scenario has no STL requirement: add an expect: {stl: ..., name: ...}",
            key=option,
        )
    if name == "all":
        return Objective(None, (), tuple(names))
    why = unknown_objective(column(name), 0, names)
    if why is not None:
        raise ConfigError(why, key=option)
    return Objective(None, (), (name,))
