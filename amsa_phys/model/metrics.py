"""Quality-of-control metrics: their names and their computation, in one module.

:data:`METRICS` are the names an ``expect`` entry may give and the columns of a sweep's
``results.csv``; :func:`block_metrics` computes them, each a pure function of the sampled
quality signal; :func:`compute_metrics` assembles them into a run's ``metrics.json``
document, overall and per phase. (The names used to live in three places, the
document in the run's module.)

The signal is sampled at the trace's log rate. ``mean_error`` is signed (signal − reference:
positive means the follower is too far behind); ``settling_time`` is the time from the
block's start to the first sample after which |error| stays within tolerance to the block's
end, provided it stays there for at least ``dwell`` seconds (None otherwise: a signal back in
the band only for its last samples has not settled); ``max_after_approach`` is the paper's
quality figure, the largest value once the signal has first come within tolerance (the
follower's first approach; None if it never does), so a start far from the reference does
not count.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from .changes import Change
from .scenariospec import Scenario

#: Metrics an ``expect`` entry may name, in the order of the columns of a sweep's
#: ``results.csv``; :func:`block_metrics` returns each of them.
METRICS = (
    "max_distance",
    "min_distance",
    "mean_error",
    "rms_error",
    "settling_time",
    "max_after_approach",
    "final_distance",
    "collisions",
)

#: Metrics that count events rather than measure the signal (plotted as counts).
COUNT_METRICS = frozenset({"collisions"})

#: Events metrics.json lists (the first ones); ``events_truncated`` says when there were more.
MAX_EVENTS = 1000


def block_metrics(
    t: np.ndarray,
    s: np.ndarray,
    start: float,
    end: float,
    reference: float,
    tolerance: float,
    event_times: Sequence[float],
    include_end: bool = False,
    dwell: float | None = None,
) -> dict[str, Any]:
    """Metrics of the samples with ``start <= t < end`` (``<= end`` when ``include_end``).

    Blocks are half-open so that a sample at a phase boundary belongs to the new phase; the
    last block (and the overall block) includes the final instant. ``dwell`` is how long the
    signal must stay in the band to count as settled: :func:`default_dwell` of the block
    when None.
    """
    mask = (t >= start) & ((t <= end) if include_end else (t < end))
    tt, ss = t[mask], s[mask]
    collisions = sum(
        1 for e in event_times if start <= e and (e <= end if include_end else e < end)
    )
    if ss.size == 0:
        return {
            "max_distance": None,
            "min_distance": None,
            "mean_error": None,
            "rms_error": None,
            "settling_time": None,
            "max_after_approach": None,
            "final_distance": None,
            "collisions": collisions,
        }
    if dwell is None:
        dwell = default_dwell(end - start)
    err = ss - reference
    inside = np.abs(err) <= tolerance
    outside = np.flatnonzero(~inside)
    settled_from = float(tt[0]) if outside.size == 0 else None
    if outside.size and outside[-1] < ss.size - 1:
        settled_from = float(tt[outside[-1] + 1])
    settling: float | None = None
    # the samples are on an exact grid but their times are floats: a hair of slack so a
    # stay of exactly ``dwell`` seconds counts
    if settled_from is not None and float(tt[-1]) - settled_from >= dwell - 1e-9:
        settling = settled_from - start
    first_in = int(np.argmax(inside)) if inside.any() else None
    return {
        "max_distance": float(ss.max()),
        "min_distance": float(ss.min()),
        "mean_error": float(err.mean()),
        "rms_error": float(np.sqrt(np.mean(err * err))),
        "settling_time": settling,
        "max_after_approach": None if first_in is None else float(ss[first_in:].max()),
        "final_distance": float(ss[-1]),
        "collisions": collisions,
    }


#: Default dwell of ``settling_time``: 10 s, or a tenth of a block shorter than 100 s.
DEFAULT_DWELL_S = 10.0


def default_dwell(length: float) -> float:
    """How long a block's signal must stay in the band to have settled, by default."""
    return min(DEFAULT_DWELL_S, 0.1 * max(length, 0.0))


def compute_metrics(
    scenario: Scenario,
    sim: Any,
    result: Any,
    wall_s: float,
    status: str,
    idle_s: float = 0.0,
) -> dict[str, Any]:
    """The ``metrics.json`` document (design.md) for a run that reached ``result.t_end``.

    ``sim`` gives the live changes (``live_changes``), ``result`` the samples and events
    (``engine.runner.RunResult``): read by name, so this module stays below the engine.

        A run that stopped before its planned end (``--duration`` shorter than the file's, the
        window closed, a fault, Ctrl-C) lists only the phases it entered; the phase it stopped
        in, and the overall block, are marked ``partial``: their checks are skipped, not failed.
        Changes made inside a phase (``new_phase: false`` entries, live changes from the
        window) are listed in that phase's ``changes``; they never start a phase of their own,
        so a session and its replay have the same phases. ``idle_s`` is wall-clock time the
        window spent paused (or finished, waiting to be closed): not part of the run's speed.
        Always valid JSON: a metric that is not a finite number (a signal near the float limit
        overflows ``rms_error``) is written as ``null`` and named in ``nonfinite``.
    """
    with np.errstate(over="ignore", invalid="ignore"):  # overflow is reported, not warned
        metrics = _metrics(scenario, sim, result, wall_s, status, idle_s)
    judged = getattr(result, "requirements", None)
    if judged is not None:  # STL requirements (``stl/``), judged on the samples
        metrics["requirements"] = judged
    return _finite(metrics)


def _finite(metrics: dict[str, Any]) -> dict[str, Any]:
    """Replace non-finite metric values by None and list where they were."""
    bad: list[str] = []
    blocks = [("overall", metrics["overall"])]
    blocks += [(f"phases[{i}]", p) for i, p in enumerate(metrics["phases"])]
    for where, block in blocks:
        for key, value in block.items():
            if isinstance(value, float) and not math.isfinite(value):
                block[key] = None
                bad.append(f"{where}.{key}")
    if bad:
        metrics["nonfinite"] = bad
    return metrics


def _metrics(
    scenario: Scenario,
    sim: Any,
    result: Any,
    wall_s: float,
    status: str,
    idle_s: float,
) -> dict[str, Any]:
    completed = status == "completed"
    end = float(scenario.duration) if completed else result.t_end
    bounds = [float(b) for b in scenario.timeline.bounds()]
    q = scenario.quality
    collisions = [e.t for e in result.events if e.kind == "collision"]
    inner = _changes_within(scenario, sim.live_changes)
    kept = scenario.timeline.phases_before(end)
    phases = []
    for i, phase in enumerate(kept):
        last = i + 1 == len(kept)
        planned_end = bounds[i + 1]
        p_end = min(planned_end, end) if last else planned_end
        start = float(phase.at)
        block: dict[str, Any] = {
            "start": start,
            "end": p_end,
            "set": {c.key: _jsonable(c.value) for c in phase.changes},
        }
        if phase.label:
            block["label"] = phase.label
        changes = [c for c in inner if start <= c["at"] < p_end or (last and c["at"] == p_end)]
        if changes:
            block["changes"] = changes
        if p_end < planned_end:
            block["partial"] = True
        if q is not None and result.samples_t.size:
            block.update(
                block_metrics(
                    result.samples_t,
                    result.samples_s,
                    start,
                    p_end,
                    q.reference,
                    q.tolerance,
                    collisions,
                    include_end=last,
                    dwell=q.dwell,
                )
            )
        else:
            block["collisions"] = sum(
                1 for t in collisions if start <= t and (t <= p_end if last else t < p_end)
            )
        phases.append(block)
    if q is not None and result.samples_t.size:
        overall = block_metrics(
            result.samples_t,
            result.samples_s,
            0.0,
            end,
            q.reference,
            q.tolerance,
            collisions,
            include_end=True,
            dwell=q.dwell,
        )
    else:
        overall = {"collisions": len(collisions)}
    if end < bounds[-1]:
        overall["partial"] = True
    # a run shorter than its scenario says what it was meant to be: a plot's title can then
    # say "1 of 4 phases", not only that the last one it ran was cut
    planned = {"end": bounds[-1], "phases": len(bounds) - 1} if end < bounds[-1] else None
    busy = wall_s - idle_s
    return {
        "scenario": scenario.name,
        "seed": scenario.seed,
        "duration": float(scenario.duration),
        "simulated": result.t_end,
        "status": status,
        **({"planned": planned} if planned else {}),
        "quality": (_quality_json(q) if q else None),
        "overall": overall,
        "phases": phases,
        "events": [
            {"t": e.t, "kind": e.kind, "detail": e.detail} for e in result.events[:MAX_EVENTS]
        ],
        **_event_counts(result),
        "wall_time_s": round(wall_s, 3),
        **({"paused_s": round(idle_s, 3)} if idle_s > 0 else {}),
        "real_time_factor": round(result.t_end / busy, 1) if busy > 0 else None,
    }


def _event_counts(result: Any) -> dict[str, Any]:
    """How many adapt switches the run made, and whether ``events`` left some out."""
    switches = getattr(result, "adapt_switches", 0)
    kept = sum(1 for e in result.events[:MAX_EVENTS] if e.kind == "adapt")
    out: dict[str, Any] = {}
    if switches:
        out["adapt_switches"] = switches
    if len(result.events) > MAX_EVENTS or switches > kept:
        out["events_truncated"] = True
    return out


def _quality_json(q: Any) -> dict[str, Any]:
    """The ``quality`` entry of ``metrics.json`` (``dwell`` only when the scenario sets it)."""
    out = {"signal": q.signal, "reference": q.reference, "tolerance": q.tolerance}
    if q.dwell is not None:
        out["dwell"] = q.dwell
    return out


def _changes_within(
    scenario: Scenario, live: list[tuple[Fraction, Change]]
) -> list[dict[str, Any]]:
    """Changes made inside phases (timeline ``new_phase: false`` and live), in time order."""
    out: dict[Fraction, dict[str, Any]] = {}
    for step in scenario.timeline.points():
        if step.starts_phase:
            continue
        entry = out.setdefault(step.at, {"at": float(step.at), "set": {}})
        entry["set"].update({c.key: _jsonable(c.value) for c in step.changes})
        if step.label:
            entry["label"] = step.label
    for at, change in live:
        entry = out.setdefault(at, {"at": float(at), "set": {}, "label": "live"})
        entry["set"][change.key] = _jsonable(change.value)
    return [out[at] for at in sorted(out)]


def _jsonable(value: Any) -> Any:
    return (
        [list(v) if isinstance(v, tuple) else v for v in value]
        if isinstance(value, tuple)
        else value
    )
