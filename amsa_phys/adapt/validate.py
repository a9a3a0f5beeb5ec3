"""``adapt --validate``: derived rules scored on held-out context sequences.

A rule set is only worth running if it beats keeping the robust fixed choice on contexts
it was *not* derived from. The held-out sequences are drawn from the sweep's own box
(``tune.contexts``: levels between the sweep's levels, random switch instants, behaviours
from the contexts' list), with their own random seed. Each is run for ``seeds`` seeds three
ways: the robust fixed choice (no rules), the rules (starting from the robust choice), and
the *oracle* schedule: at each true switch instant, the best choice of the sweep cell
nearest the new context (what perfect estimators and rules would set; for a context between
the sweep's levels it is the nearest cell's best, not a re-tuned one). The rules *lose*
when on any sequence their seed-mean metric is more than ``tolerance`` above the robust
choice's.
"""

from __future__ import annotations

import datetime
import math
import os
import statistics
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..model.scenario import Scenario
from ..tune.contexts import Axis, Sequence, box, sequences
from ..tune.evaluate import evaluate
from .derive import Cell, Derivation


@dataclass
class Row:
    """One held-out sequence: its contexts and the seed means of the three ways."""

    sequence: Sequence
    robust: float
    oracle: float
    adaptive: float
    #: each way's value per seed (seeds 1..n), so a results file shows the spread
    seeds: dict[str, list[float]] = field(default_factory=dict)

    @property
    def change(self) -> float:
        """The rules' mean relative to the robust choice's (-0.1: 10 % better)."""
        if not (math.isfinite(self.robust) and self.robust > 0):
            return math.inf
        return self.adaptive / self.robust - 1.0


def nearest(cells: list[Cell], axes: list[Axis], context: dict[str, Any]) -> Cell:
    """The cell whose context is nearest ``context`` (scaled by each axis's span)."""

    def distance(cell: Cell) -> float:
        d = 0.0
        for a in axes:
            mine, theirs = context.get(a.key), cell.context.get(a.key)
            if a.choices:
                d += 0.0 if mine == theirs else 1.0
            else:
                d += abs(float(mine) - float(theirs)) / ((a.hi - a.lo) or 1.0)
        return d

    return min((c for c in cells if c.best), key=distance)


def validate(
    scenario: Scenario,
    found: Derivation,
    contexts: dict[str, dict[str, Any]],
    count: int = 5,
    seeds: int = 3,
    duration: float = 600.0,
    seed: int = 1000,
    report: Callable[[str], None] | None = None,
) -> list[Row]:
    """Score ``found``'s rules on ``count`` held-out sequences; one :class:`Row` each."""
    # the draws span the cells' box: a catch-up (a cell started elsewhere) is not a context
    axes = box(scenario, {k: v for k, v in contexts.items() if k not in found.catch_ups})
    rows = []
    for sequence in sequences(axes, count, duration, seed):
        oracle_plan = [
            (at, nearest(found.cells, axes, sets).best) for at, sets in sequence.segments
        ]
        ways: dict[str, list[float]] = {"robust": [], "oracle": [], "adaptive": []}
        for s in range(1, seeds + 1):
            cases = {
                "robust": evaluate(scenario, sequence, found.robust, s, found.metric, duration),
                "adaptive": evaluate(
                    scenario, sequence, found.robust, s, found.metric, duration, found.rules
                ),
                "oracle": evaluate(
                    scenario, sequence, {}, s, found.metric, duration, None, oracle_plan
                ),
            }
            for way, value in cases.items():
                ways[way].append(math.inf if value is None else value)
        means = (statistics.fmean(ways[w]) for w in ("robust", "oracle", "adaptive"))
        row = Row(sequence, *means, seeds={w: list(v) for w, v in ways.items()})
        rows.append(row)
        if report is not None:
            report(line(row))
    return rows


def line(row: Row) -> str:
    """One table row: the three means and the rules' change against the robust choice."""
    return (
        f"{row.robust:.4g} | {row.oracle:.4g} | {row.adaptive:.4g} | {100 * row.change:+.1f} % "
        f"| {row.sequence.describe()}"
    )


HEADER = "robust | oracle | rules | rules vs robust | held-out sequence"


def loses(rows: list[Row], tolerance: float) -> list[Row]:
    """The sequences on which the rules are more than ``tolerance`` worse than robust."""
    return [r for r in rows if r.change > tolerance]


def short_of_oracle(rows: list[Row], gain: float = 0.1) -> tuple[list[Row], list[Row]]:
    """(sequences where the oracle gains at least ``gain`` over the robust choice, those of
    them where the rules do not): where adaptation is worth having, how often the rules
    deliver it (a rule set that never loses may still never switch)."""
    worth = [
        r
        for r in rows
        if math.isfinite(r.robust) and r.robust > 0 and r.oracle <= (1.0 - gain) * r.robust
    ]
    return worth, [r for r in worth if not r.adaptive <= (1.0 - gain) * r.robust]


def results(rows: list[Row], found: Derivation, settings: dict[str, Any]) -> dict[str, Any]:
    """The scored rules as a results file: what ``--results`` writes and the docs render.

    ``settings`` says how they were scored (sequences, seeds, duration, tolerance, the
    command); the machine's load and the date say in which sitting (the numbers do not
    depend on them: every run is a pure function of scenario and seed).
    """
    return {
        "metric": found.metric,
        "robust": dict(found.robust),
        "settings": settings,
        "load": [round(x, 2) for x in os.getloadavg()],
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "rows": [
            {
                "sequence": r.sequence.describe(),
                "segments": [[at, sets] for at, sets in r.sequence.segments],
                "robust": r.robust,
                "oracle": r.oracle,
                "rules": r.adaptive,
                "change": r.change,
                "seeds": r.seeds,
            }
            for r in rows
        ],
    }


def markdown(doc: dict[str, Any]) -> str:
    """The docs' table of a results file (seed means; the rules' change against robust)."""
    robust = ", ".join(f"{k.rsplit('.', 1)[-1]} {v}" for k, v in doc["robust"].items())
    lines = [
        f"| robust {robust} | oracle | rules | rules vs robust | held-out sequence |",
        "| --- | --- | --- | --- | --- |",
    ]
    for r in doc["rows"]:
        change = "" if not math.isfinite(r["change"]) else f"{100 * r['change']:+.1f} %"
        lines.append(
            f"| {r['robust']:.4g} | {r['oracle']:.4g} | {r['rules']:.4g} "
            f"| {change.replace('-', '−')} | {r['sequence']} |"
        )
    s = doc["settings"]
    load = "–".join(f"{x:g}" for x in doc["load"])
    lines += [
        "",
        f"*{s['sequences']} sequences × {s['seeds']} seeds of {s['duration']:g} s, "
        f"{doc['metric']} seed means (load {load}, {doc['date'][:10]}). Regenerate, DIR "
        f"the sweep's output: `{s['command']}`.*",
    ]
    return "\n".join(lines) + "\n"
