"""A falsification's files: ``results.csv``, ``worst.yaml`` and ``convergence.png``."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Any

import yaml

from ..atomic import write_atomic
from ..errors import one_line
from ..model.wording import plural
from ..runs.resolve import resolved_scenario
from ..runs.sweep import Job, prepare_job
from .objective import Objective
from .search import Progress, Settings

#: libyaml's emitter when PyYAML has it (as a run's scenario.yaml).
_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


def write_results(rows: list[dict[str, Any]], keys: list[str], path: Path) -> None:
    """results.csv: a sweep's columns (``run``, the searched parameters, ``seed_index``,
    ``seed``, ``error``, the metrics) then ``generation`` (and ``robustness``), sorted by
    run, so the file never depends on completion order."""
    rows = sorted(rows, key=lambda r: r["run"])
    fields = ["run", *keys, "seed_index", "seed", "error"]
    tail = ["generation", "robustness"]
    for r in rows:
        for k in r:
            if k not in fields and k not in tail:
                fields.append(k)
    fields += [k for k in tail if any(k in r for r in rows)]
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=fields, lineterminator="\n")
    writer.writeheader()
    for r in rows:
        writer.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in fields})
    write_atomic(path, buf.getvalue())


def point_of(row: dict[str, Any], keys: list[str]) -> tuple[tuple[str, Any], ...]:
    """The searched settings of a result row."""
    return tuple((k, row[k]) for k in keys)


def write_worst(
    row: dict[str, Any], keys: list[str], settings: Settings, headline: str, path: Path
) -> None:
    """worst.yaml: the resolved scenario of the worst run (world inlined, every value, its
    duration and seed), so ``amsa-phys run worst.yaml`` replays it and measures the same."""
    job = Job(
        0, str(settings.scenario), point_of(row, keys), 0, settings.run_seed, (), settings.duration
    )
    doc = resolved_scenario(prepare_job(job))
    doc["name"] = f"{doc['name']}-worst"
    head = "".join(f"# {one_line(line)}\n" for line in headline.splitlines())
    write_atomic(path, head + yaml.dump(doc, Dumper=_DUMPER, sort_keys=False))


def describe_value(value: float | None) -> str:
    """``5.0354``, or what an infinite value means."""
    if value is None:
        return "none (never reached)"
    if math.isinf(value):
        return "-inf (a fault)" if value < 0 else "inf (no check judged)"
    return f"{value:.6g}"


def headline(progress: Progress, k: int, keys: list[str], objective: Objective, total: int) -> str:
    """The one line printed at the end: the worst context, its value, and whether it breaks
    a requirement."""
    row = progress.rows[k]
    verdict = progress.verdicts[k]
    context = ", ".join(f"{key}={row[key]}" for key, _ in point_of(row, keys))
    line = (
        f"worst of {plural(len(progress.rows), 'run')}"
        + (f" (of a budget of {total})" if len(progress.rows) < total else "")
        + f": {context} -> {objective.label} = {describe_value(verdict.value)}"
        + f" (run {row['run']}, generation {row['generation']})"
    )
    if verdict.violated:
        line += f"; VIOLATION: {verdict.why}"
    elif objective.metric is not None and not objective.checks:
        line += f"; no expect check on {objective.metric} to violate"
    else:
        line += "; no violation"
    return one_line(line)
