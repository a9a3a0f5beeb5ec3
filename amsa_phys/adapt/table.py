"""A context sweep's ``results.csv`` read for ``amsa-phys adapt``: streamed and judged.

``adapt`` turns the file's numbers into rules a robot will run, so it trusts none of them:
every axis cell is judged by the same rules a scenario's value is (``resolve_change``: the
parameter's type and range), every metric cell must be empty (a failed run) or a finite
number, and the first bad cell is one line naming the file, the row and the column. The
file is read a row at a time (a regular file of at most ``MAX_RESULTS_BYTES``, no line over
``MAX_LINE_CHARS``) and only per-(cell, grid point) sums are kept, so memory is bounded by
the grid's size (at most ``MAX_POINTS`` points), not by the file's.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError, one_line
from ..model.changes import resolve_change
from ..model.params import short_repr
from ..model.world import WorldSpec
from ..runs.results import bounded_lines, open_results
from ..tune.objective import ROBUSTNESS

#: Columns of every results.csv that are not metrics (never a ``--metric``).
NOT_METRICS = ("run", "seed_index", "seed", "error")
#: Distinct (context cell, tuned point) pairs kept in memory; a larger sweep is refused.
MAX_POINTS = 100_000


@dataclass
class Stats:
    """One grid point in one context cell: the metric's sum over seeds, and the failures."""

    total: float = 0.0
    count: int = 0
    failed: int = 0

    @property
    def mean(self) -> float:
        """Seed mean of the metric (NaN when no run gave a value)."""
        return self.total / self.count if self.count else math.nan

    @property
    def stable(self) -> bool:
        """Every run at this point finished with a value (a failure counts as unstable)."""
        return self.count > 0 and self.failed == 0


@dataclass
class SweepTable:
    """What ``adapt`` keeps of a results.csv: axes, and the stats of each cell's points."""

    axes: list[str]
    context_axes: list[str]
    tuned: list[str]
    stats: dict[tuple[Any, ...], dict[tuple[Any, ...], Stats]] = field(default_factory=dict)
    rows: int = 0


def read_table(
    path: Path,
    metric: str,
    world: WorldSpec,
    contexts: dict[str, dict[str, Any]],
    watched: set[str],
) -> SweepTable:
    """Stream ``path`` into per-cell stats of ``metric``; refuse the first bad cell."""
    handle = open_results(path)  # a FIFO, a file over the limit: refused before a read
    with handle:
        reader = csv.reader(bounded_lines(handle, path))
        try:
            return _read(reader, path, metric, world, contexts, watched)
        except UnicodeDecodeError as exc:
            raise ConfigError(
                f"not a results.csv: not UTF-8 text (byte {exc.start})", file=path
            ) from None
        except csv.Error as exc:
            raise ConfigError(
                f"not a results.csv: {exc}", file=path, line=reader.line_num
            ) from None
        except OSError as exc:
            raise ConfigError(f"cannot read: {exc.strerror}", file=path) from None


def _read(
    reader: Iterator[list[str]],
    path: Path,
    metric: str,
    world: WorldSpec,
    contexts: dict[str, dict[str, Any]],
    watched: set[str],
) -> SweepTable:
    fields = next(reader, [])
    if fields[:1] != ["run"] or any(k not in fields for k in NOT_METRICS):
        missing = [k for k in NOT_METRICS if k not in fields] or ["run (first)"]
        raise ConfigError(
            f"not a sweep's results.csv: no {', '.join(missing)} column", file=path, line=1
        )
    axes = fields[1 : fields.index("seed_index")]
    metrics = fields[fields.index("error") + 1 :]
    if metric not in metrics:
        what = (
            "is not a metric (a column every sweep has)"
            if metric in NOT_METRICS or metric in axes
            else "is not a column of the sweep"
        )
        known = ", ".join(one_line(m) for m in metrics[:8]) + (", ..." if len(metrics) > 8 else "")
        raise ConfigError(f"{one_line(metric)} {what}; its metrics: {known}", key="--metric")
    if "context" in axes and not contexts:
        raise ConfigError(
            "the sweep has a context axis but its scenario has no sweep.contexts; "
            "give the scenario the sweep ran (--scenario)",
            file=path,
        )
    context_axes = [a for a in axes if a == "context" or a in watched]
    tuned = [a for a in axes if a not in context_axes]
    table = SweepTable(axes, context_axes, tuned)
    # a requirement's robustness is higher-is-better: kept negated, so lower wins throughout
    sign = -1.0 if metric.startswith(ROBUSTNESS) else 1.0
    at = {name: fields.index(name) for name in fields}
    judged: dict[tuple[str, str], Any] = {}
    points = 0
    for raw in reader:
        line = getattr(reader, "line_num", 0)
        if not raw:
            continue
        if len(raw) != len(fields):
            raise ConfigError(
                f"not a sweep's results.csv: {len(raw)} cells where the header has {len(fields)}",
                file=path,
                line=line,
            )
        values = []
        for axis in axes:
            text = raw[at[axis]]
            key = (axis, text)
            if key not in judged:
                if len(judged) >= MAX_POINTS:
                    raise ConfigError(
                        f"more than {MAX_POINTS} distinct axis values: not a sweep adapt reads",
                        file=path,
                        line=line,
                    )
                judged[key] = _judge(axis, text, world, contexts, path, line)
            values.append(judged[key])
        cell = tuple(v for a, v in zip(axes, values, strict=True) if a in context_axes)
        point = tuple(v for a, v in zip(axes, values, strict=True) if a not in context_axes)
        by_point = table.stats.setdefault(cell, {})
        if point not in by_point:
            points += 1
            if points > MAX_POINTS:
                raise ConfigError(
                    f"more than {MAX_POINTS} grid points: not a sweep adapt reads",
                    file=path,
                    line=line,
                )
            by_point[point] = Stats()
        stats = by_point[point]
        value = _metric(raw[at[metric]], metric, path, line)
        if raw[at["error"]] or value is None:
            stats.failed += 1
        else:
            stats.total += sign * value
            stats.count += 1
        table.rows += 1
    return table


def _judge(
    axis: str,
    text: str,
    world: WorldSpec,
    contexts: dict[str, dict[str, Any]],
    path: Path,
    line: int,
) -> Any:
    """An axis cell as the value the sweep set (a context's name, or a checked parameter)."""
    if axis == "context":
        if text not in contexts:
            raise ConfigError(
                f"context: {short_repr(text)} is not in the scenario's sweep.contexts",
                file=path,
                line=line,
            )
        return text
    try:
        value: Any = float(text)
    except ValueError:
        value = text
    try:
        change = resolve_change(axis, value, world)
    except ValueError as exc:
        raise ConfigError(
            f"{one_line(axis)}: {short_repr(text)}: {exc}", file=path, line=line
        ) from None
    out = change.value
    if isinstance(out, float) and not math.isfinite(out):
        raise ConfigError(
            f"{one_line(axis)}: {short_repr(text)} is not a finite number", file=path, line=line
        )
    return out


def _metric(text: str, metric: str, path: Path, line: int) -> float | None:
    """A metric cell: empty (no value: the run failed or never settled) or a finite number."""
    if not text:
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
        bad = "not a number"
    else:
        bad = "not a finite number"
    if not math.isfinite(value):
        raise ConfigError(f"{one_line(metric)}: {short_repr(text)} is {bad}", file=path, line=line)
    return value
