"""``amsa-phys plot`` on a falsification's directory: its runs as samples of the box."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..errors import ConfigError, one_line
from ..falsify.records import read_record
from ..runs.rundir import check_output
from ..runs.sweep import read_results

#: what ``falsify`` writes to record its search (in the directory, or above a trial's)
RECORD = "falsify.json"


def record_of(folder: Path) -> Path | None:
    """The falsify.json of a falsification's directory or of one of its ``trial-NNN``."""
    places = [folder, folder.parent] if folder.name.startswith("trial-") else [folder]
    for place in places:
        if (place / RECORD).is_file():
            return place / RECORD
    return None


def _read_record(path: Path) -> dict[str, Any]:
    """The record's fields the plot reads, checked (a directory handed over is data)."""
    doc = read_record(path, "a falsification's record")
    for key in ("objective", "scenario"):
        if not isinstance(doc.get(key), str | None):
            raise ConfigError("is not text (not a falsification's record)", file=path, key=key)
    return doc


def plot_falsify(folder: Path, args: argparse.Namespace) -> int:
    """samples.png: every run at its context, coloured by the metric (default: what the
    search optimised), the falsifying runs ringed and the worst starred."""
    from ..plots.samples import falsifying, plot_samples  # matplotlib: once the rows are in

    record = record_of(folder)
    assert record is not None  # the caller found it
    doc = _read_record(record)
    rows, axes = read_results(folder / "results.csv")
    columns = set(rows[0]) if rows else set()
    objective = str(doc.get("objective") or "robustness")
    metric = args.metric or (objective if objective in columns else "rms_error")
    if rows and metric not in columns:
        known = sorted(c for c in columns if c not in {"run", "seed", "seed_index", "error"})
        raise ConfigError(
            f"no column {metric} in results.csv (it has {', '.join(known)})",
            key="--metric",
        )
    scenario = Path(str(doc.get("scenario") or folder.name)).stem
    maximise = not objective.startswith("robustness")
    out = Path(args.output) if args.output else folder / "samples.png"
    check_output(out, "--output")
    bad = falsifying(rows)
    runs = f"{len(rows)} run{'s' if len(rows) != 1 else ''}"
    title = f"{scenario}: {metric} of {runs}"
    if "robustness" in columns:
        title += f", {len(bad)} falsifying"
    plot_samples(rows, axes, metric, out, one_line(title), scenario, objective, maximise=maximise)
    print(one_line(f"wrote {out}"))
    return 0
