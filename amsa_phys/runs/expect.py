"""Checking a run against the scenario's ``expect`` entries (metrics and trace windows)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..model.scenario import Expectation
from ..stl.requirement import reads_until

#: how a trace check that saw no logged sample begins its note
NO_SAMPLE = "no sample"


@dataclass
class Check:
    """One expectation and what was measured."""

    expectation: Expectation
    value: float | None
    passed: bool
    skipped: bool = False
    why: str = ""  # why a metric check was skipped (a phase cut short or not reached)
    #: why a trace check saw no sample, or how much of its window the run covered
    note: str = ""
    #: which statistic of a trace window ``value`` is: "max" (against ``below``) or "min"
    stat: str = ""
    #: a two-sided trace window's other extreme (shown beside ``value``)
    other: float | None = None

    @property
    def measured(self) -> str:
        """``0.6576``, or ``max 10.41`` for a trace window (its extreme sample)."""
        if self.value is None:
            return "none"
        if self.stat and self.other is not None:  # both bounds: both extremes
            low, high = sorted((self.value, self.other))
            return f"min {low:.4g}, max {high:.4g}"
        return f"{self.stat} {self.value:.4g}" if self.stat else f"{self.value:.4g}"

    @property
    def what(self) -> str:
        """``max_distance (phase 1)`` or ``Comp.out in [30, end] s``."""
        return describe_what(self.expectation)

    @property
    def bound(self) -> str:
        """``below 26 and above 2``."""
        return describe_bound(self.expectation)

    @property
    def verdict(self) -> str:
        """pass, FAIL, skipped, or "no sample" (a trace window the run never logged)."""
        if self.value is None and self.note.startswith(NO_SAMPLE):
            return "no sample" if self.skipped else "FAIL"
        return "skipped" if self.skipped else ("pass" if self.passed else "FAIL")

    def describe(self) -> str:
        """``max_distance (phase 1) = 24.3, below 26: pass``.

        A check that judged nothing leads with its verdict and says why once, as a skipped
        metric does: ``Comp.out in [3, 4] s: skipped (no sample: the window starts after
        the run's end at t=2 s)``.
        """
        if self.value is None and self.note:
            return f"{self.what}: {'skipped' if self.skipped else 'FAIL'} ({self.note})"
        if self.skipped:
            return f"{self.what}: skipped ({self.why})"
        note = f" ({self.note})" if self.note else ""
        return f"{self.what} = {self.measured}{note}, {self.bound}: {self.verdict}"


def describe_what(e: Expectation) -> str:
    """What an expectation measures: ``max_distance (phase 1)``, ``Comp.out in [30, end] s``
    or ``requirement band``."""
    if e.stl is not None:
        return f"requirement {e.name}"
    if e.trace is not None:
        lo = f"{e.after:g}" if e.after is not None else "0"
        hi = f"{e.before:g}" if e.before is not None else "end"
        return f"{e.trace} in [{lo}, {hi}] s"
    return f"{e.metric}" + (f" (phase {e.phase})" if e.phase is not None else "")


def describe_bound(e: Expectation) -> str:
    """An expectation's bounds: ``below 26 and above 2`` (an STL requirement: its formula)."""
    if e.stl is not None:
        return "robustness >= 0"
    parts = []
    if e.below is not None:
        parts.append(f"below {e.below:g}")
    if e.above is not None:
        parts.append(f"above {e.above:g}")
    return " and ".join(parts)


def check_expectations(
    expect: list[Expectation],
    metrics: dict[str, Any],
    trace: Path | tuple[list[str], np.ndarray] | None = None,
) -> list[Check]:
    """Evaluate every expectation; a metric that is null (never settled) fails a bound.

    ``trace`` is the run's ``trace.csv``, or its header and rows already in memory. A trace
    check reports the sample that came closest to breaking (or broke) its bound.
    """
    checks = []
    columns: tuple[list[str], np.ndarray] | None = None
    end = float(metrics.get("simulated", 0.0))
    for e in expect:
        if e.stl is not None:
            checks.append(_stl_check(e, metrics))
            continue
        if e.trace is not None:
            if columns is None:
                columns = _read(trace)
            cut = bool(metrics.get("overall", {}).get("partial"))
            checks.append(_trace_check(e, *columns, end, cut))
            continue
        why = skip_reason(e, metrics)
        if why is not None:
            broken = already_broken(e, metrics)
            if broken is None:
                checks.append(Check(e, None, True, skipped=True, why=why))
            else:
                value, note = broken
                checks.append(Check(e, value, False, note=note))
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


def _stl_check(e: Expectation, metrics: dict[str, Any]) -> Check:
    """An STL requirement's check: its robustness from ``metrics.json``'s ``requirements``
    (judged on the run's samples; ``stl/requirement.py``), with the instant and
    the comparison that set it."""
    entry = (metrics.get("requirements") or {}).get(e.name)
    reached = float(metrics.get("simulated", 0.0))
    until = reads_until(str(e.stl))
    if until > reached + 1e-9:  # its windows were cut by the run's end: not judged
        why = f"it reads until t={until:g} s; the run ended at t={reached:g} s"
        return Check(e, None, True, skipped=True, why=why)
    if entry is None:
        return Check(e, None, False, note="not judged: the run kept no samples of it")
    if entry.get("verdict") == "skipped":  # judged nothing: its windows were cut
        return Check(e, None, True, skipped=True, why=str(entry.get("note") or "not judged"))
    rob = entry.get("robustness")
    note = ""
    if entry.get("instant") is not None:
        note = f"set at t={entry['instant']:g} s by {entry.get('atom', '?')}"
    if entry.get("note"):
        note = f"{entry['note']}; {note}" if note else entry["note"]
    return Check(e, rob, entry.get("verdict") == "pass", note=note, stat="robustness")


def skip_reason(e: Expectation, metrics: dict[str, Any]) -> str | None:
    """Why a metric check cannot be judged on this run, or None if it can.

    A phase the run never reached, or a block the run stopped inside (``--duration`` shorter
    than the file's, the window closed early), is not judged: the bound is about the whole
    phase, and half a phase would fail (or pass) for the wrong reason -- unless it has already
    failed for good (:func:`already_broken`), which the caller checks.
    """
    if e.trace is not None or e.stl is not None:
        return None
    reached = metrics.get("simulated", 0.0)
    if e.phase is not None and e.phase >= len(metrics["phases"]):
        return f"phase {e.phase} not reached: the run ended at t={reached:g} s"
    block = metrics["overall"] if e.phase is None else metrics["phases"][e.phase]
    if block.get("partial"):
        what = "the run" if e.phase is None else f"phase {e.phase}"
        return f"{what} was cut short at t={reached:g} s"
    return None


#: Metrics that can only move one way as a block goes on, and the bound they can only break
#: for good: a count of collisions and a maximum only grow (``below``), a minimum only
#: shrinks (``above``). ``max_after_approach`` is a maximum once the first approach has
#: happened (None before it: nothing is known yet).
MONOTONE = {
    "collisions": "below",
    "max_distance": "below",
    "max_after_approach": "below",
    "min_distance": "above",
}


def already_broken(e: Expectation, metrics: dict[str, Any]) -> tuple[float, str] | None:
    """``(value, note)`` if a check of a block the run stopped inside has already failed.

    The rest of a cut-short block could not have repaired a monotone metric: 1 collision
    at t = 9.7 s is a failed ``collisions below 1`` however the run would have gone on, so
    that check is FAIL, not skipped (a skipped check passes). Any other partial check stays
    skipped (:func:`skip_reason`).
    """
    if e.metric not in MONOTONE or e.trace is not None or e.stl is not None:
        return None
    if e.phase is not None and e.phase >= len(metrics["phases"]):
        return None  # never reached: nothing measured
    block = metrics["overall"] if e.phase is None else metrics["phases"][e.phase]
    value = block.get(e.metric)
    if not block.get("partial") or value is None:
        return None
    side = MONOTONE[e.metric]
    bound = e.below if side == "below" else e.above
    if bound is None:
        return None
    broken = value >= bound if side == "below" else value <= bound
    if not broken:
        return None
    reached = metrics.get("simulated", 0.0)
    why = {"collisions": "a count", "min_distance": "a minimum"}.get(e.metric, "a maximum")
    why += " only grows" if side == "below" else " only shrinks"
    note = f"already broken when the run was cut short at t={reached:g} s: {why}"
    return float(value), note


def _read(trace: Path | tuple[list[str], np.ndarray] | None) -> tuple[list[str], np.ndarray]:
    if isinstance(trace, tuple):
        return trace
    if trace is None:
        raise ValueError("trace checks need the run's trace.csv")
    with open(trace, encoding="utf-8") as fh:
        header = fh.readline().strip().split(",")
    return header, np.loadtxt(trace, delimiter=",", skiprows=1, ndmin=2)


def _trace_check(
    e: Expectation, header: list[str], data: np.ndarray, end: float, cut: bool = False
) -> Check:
    """Judge every logged sample of the window; a window without one is said to be so.

    A window that starts after the run's end (``end``: cut by ``--duration``, a fault or
    Ctrl-C) checked no sample and is skipped, visibly; one inside the run that caught no
    logged instant fails (its bound was never checked). A window running past the end
    says up to when it was checked. In a run ``cut`` short, a window the run stopped
    inside is judged only if a sample broke the bound (that sample is real); had it held,
    the check is skipped like a metric of a cut phase: the rest of the window might not
    have held.
    """
    t = data[:, 0]
    mask = np.ones_like(t, dtype=bool)
    if e.after is not None:
        mask &= t >= e.after
    if e.before is not None:
        mask &= t <= e.before
    values = data[mask, header.index(e.trace)]
    if values.size == 0:
        if e.after is not None and e.after > end:
            note = f"{NO_SAMPLE}: the window starts after the run's end at t={end:g} s"
            return Check(e, None, True, skipped=True, note=note)
        note = f"{NO_SAMPLE}: no logged instant in the window; widen it or raise log_rate"
        return Check(e, None, False, note=note)
    past_end = e.before is None or e.before > end
    note = f"checked up to the run's end at t={end:g} s" if past_end and e.before else ""
    worst: float | None = None
    stat = ""
    ok = True
    low = float(values.min())
    high = float(values.max())
    if e.above is not None:
        worst, stat = low, "min"
        ok = ok and low > e.above
    if e.below is not None:
        if worst is None or high >= e.below:
            worst, stat = high, "max"
        ok = ok and high < e.below
    other = None
    if e.above is not None and e.below is not None:
        other = high if worst == low and stat == "min" else low
    if ok and cut and past_end:
        why = f"the run was cut short at t={end:g} s inside the window; held until then"
        return Check(e, worst, True, skipped=True, why=why, stat=stat, other=other)
    return Check(e, worst, ok, note=note, stat=stat, other=other)
