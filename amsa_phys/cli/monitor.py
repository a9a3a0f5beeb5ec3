"""Evaluate an STL formula's robustness on a finished run's trace.

The run directory is read as data only: the columns of ``trace.csv`` and their samples, never
its ``scenario.yaml`` (whose templates would be imported to load it). The log period is the
spacing of the trace's ``t`` column, which must be even (a formula's time bounds count
samples of it).
"""

from __future__ import annotations

import argparse
import json
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np

from ..errors import ConfigError, one_line
from ..model.rates import MAX_RATE_HZ

#: Spacing of logged instants may differ from the first by this much (their sum rounds).
SPACING_TOL = 1e-9


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys monitor``."""
    p.add_argument("rundir", help="a run directory (its trace.csv is read)")
    p.add_argument("formula", help='an STL formula, e.g. "always[10:60](Comp.out <= 3)"')
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")


def read_trace(path: Path, wanted: set[str]) -> tuple[list[str], np.ndarray, dict[str, np.ndarray]]:
    """The header, the ``t`` column and the ``wanted`` columns of ``trace.csv`` (only those
    are kept in memory), every row. Read through the reader ``plot`` and ``view`` use, so a
    file that is not a whole trace (a row wider or narrower than the header, a cell that is
    not a number, ``t`` going back) is refused the same way: one line naming the file and
    its line, never judged as if it were a run's."""
    from ..engine.traceread import read_header, read_rows

    header = read_header(path)
    # every row: a formula's windows count samples, so none may be skipped
    names, data, _stride = read_rows(path, frozenset(wanted), max_cells=sys.maxsize)
    out = {c: data[:, k] for k, c in enumerate(names)}
    return header, out["t"], out


def log_period(t: np.ndarray, path: Path) -> Fraction:
    """The trace's sampling period, from its ``t`` column (even spacing required)."""
    if t.size < 2:
        raise ConfigError("the trace holds fewer than two samples", file=path)
    if not np.isfinite(t).all():
        raise ConfigError("the trace's t column holds a value that is not a number", file=path)
    steps = np.diff(t)
    first = float(steps[0])
    if first <= 0 or np.abs(steps - first).max() > SPACING_TOL * max(1.0, float(t[-1])):
        raise ConfigError("the trace's instants are not evenly spaced", file=path)
    if first < (1 - SPACING_TOL) / MAX_RATE_HZ:  # its period would round to 0 (a traceback)
        raise ConfigError(
            f"the trace's instants are {first:g} s apart: no run logs faster than "
            f"{MAX_RATE_HZ:,} Hz",
            file=path,
        )
    return Fraction(first).limit_denominator(1_000_000)


def run(args: argparse.Namespace) -> int:
    """Print the formula's robustness at t = 0 on the run; exit 0 if it holds, 1 if not."""
    from ..model.suggest import did_you_mean
    from ..runs.rundata import refuse_sweep_dir
    from ..stl.requirement import TIME, Requirement, check_formula, judge
    from ..stl.syntax import FormulaError, parse

    rundir = Path(args.rundir)
    if rundir.is_file():  # the trace itself, or the run's scenario.yaml: name the directory
        raise ConfigError(
            f"not a directory: give the run directory ({rundir.parent}), whose trace.csv is read",
            file=rundir,
        )
    refuse_sweep_dir(rundir, "monitor")
    path = rundir / "trace.csv"
    if not path.is_file():
        raise ConfigError("no trace.csv: not a run directory", file=Path(args.rundir))
    try:
        wanted = parse(args.formula).signals()
    except FormulaError as exc:
        raise ConfigError(f"the formula does not parse: {exc}", key="FORMULA") from None
    header, t, cols = read_trace(path, wanted)
    period = log_period(t, path)
    end = Fraction(float(t[-1])).limit_denominator(1_000_000)
    try:
        node = check_formula(args.formula, header[1:], 1 / period, end, did_you_mean)
    except ValueError as exc:
        raise ConfigError(str(exc), key="FORMULA") from None
    req = Requirement("formula", args.formula, node)
    signals = {k: v for k, v in cols.items() if k != TIME}
    entry = judge([req], t, signals, period)[0]["formula"]
    if args.json:
        print(json.dumps(entry, allow_nan=False))
    else:
        rob = entry["robustness"]
        text = "none" if rob is None else f"{rob:.6g}"
        where = ""
        if entry.get("instant") is not None:
            where = f", set at t={entry['instant']:g} s by {entry.get('atom', '?')}"
        note = f" ({entry['note']})" if entry.get("note") else ""
        print(one_line(f"robustness {text}{note}: {entry['verdict']}{where}"))
    return 0 if entry["verdict"] == "pass" else 1
