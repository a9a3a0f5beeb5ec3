"""A sweep's ``results.csv``: its metric columns, and reading it back (plots, reports).

Split from ``sweep.py``, which writes the file; the metric names come from the one module
that owns them (``model/metrics.py``).
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
import stat
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import IO, Any

from ..errors import ConfigError
from ..model.metrics import METRICS
from ..model.params import short_repr
from ..model.suggest import did_you_mean
from ..model.yamlio import read_regular_file
from ..requirements.objective import requirement_of, unknown_objective

#: The largest results.csv read (``plot``, ``adapt``): a row is ~100-500 bytes, so this is
#: hundreds of thousands of runs; a larger file is refused before a byte of it is read.
MAX_RESULTS_BYTES = 128 << 20
#: The longest line of a results.csv read as a stream (a row is far shorter)
MAX_LINE_CHARS = 1 << 20
#: What a refusal says was expected
EXPECTED = "a sweep's results.csv"

#: Metric columns written for the overall block and each phase.
METRIC_KEYS = METRICS


def metric_names(n_phases: int) -> list[str]:
    """The metric columns of ``results.csv``: overall, then ``phase<i>.<metric>``."""
    return [*METRIC_KEYS, *(f"phase{i}.{k}" for i in range(n_phases) for k in METRIC_KEYS)]


#: ``phase<i>.<metric>``: a phase's column, whose metric part may be right and its phase absent
_PHASE_METRIC = re.compile(r"phase\d+\.(.+)")


def unknown_metric(metric: str, n_phases: int) -> str | None:
    """Why ``metric`` names no column of a sweep with ``n_phases`` phases (None if it does).

    A misspelt name gets the nearest column (``max_after`` -> ``max_after_approach``); a
    known metric of a phase the runs do not reach gets none (``phase1.rms_error`` is not a
    typo of ``phase0.rms_error``): the list of phases that follows says which exist.
    """
    if metric in metric_names(n_phases):
        return None
    of_phase = _PHASE_METRIC.fullmatch(metric)
    if of_phase and of_phase.group(1) in METRIC_KEYS:
        hint = ""
    else:
        hint = did_you_mean(metric, metric_names(n_phases))
    phases = (
        f"; or phase<i>.<metric> for i in 0..{n_phases - 1}"
        if n_phases > 1
        else "; or phase0.<metric>" * n_phases
    )
    return f"unknown metric {metric!r}{hint}; known: {', '.join(METRIC_KEYS)}{phases}"


def unknown_sweep_metric(metric: str, n_phases: int, requirements: Sequence[str]) -> str | None:
    """Why ``metric`` names no column of a sweep's ``results.csv`` (None if it does): a
    metric as :func:`unknown_metric` says, or ``robustness.NAME`` of one of the scenario's
    STL ``requirements`` (the column each adds)."""
    if requirement_of(metric) is not None:
        return unknown_objective(metric, n_phases, requirements)
    return unknown_metric(metric, n_phases)


def read_results(path: Path) -> tuple[list[dict[str, Any]], list[str]]:
    """``results.csv`` back as rows and the grid axes (the columns between run and seed_index).

    Axis values that read as numbers become floats (so a numeric axis plots as one), metrics
    become floats or None (an empty cell: never settled, or the run failed). A file that is
    not a sweep's results (binary, a column missing, a row of the wrong width, text where a
    metric belongs) is refused with one line naming the line.
    """
    raw = read_regular_file(Path(path), MAX_RESULTS_BYTES, EXPECTED)  # a FIFO, 1 GiB: refused
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(
            f"not a results.csv: not UTF-8 text (byte {exc.start})", file=path
        ) from None
    try:
        table = list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as exc:
        raise ConfigError(f"not a results.csv: {exc}", file=path) from None
    fields = table[0] if table else []
    needed = ("run", "seed_index", "seed", "error")
    if fields[:1] != ["run"] or any(k not in fields for k in needed):
        missing = [k for k in needed if k not in fields] or ["run (first)"]
        raise ConfigError(
            f"not a sweep's results.csv: no {', '.join(missing)} column", file=path, line=1
        )
    axes = fields[1 : fields.index("seed_index")]
    metrics = fields[fields.index("error") + 1 :]
    rows = []
    for line, raw in enumerate(table[1:], start=2):
        if not raw:
            continue
        if len(raw) != len(fields):
            raise ConfigError(
                f"not a sweep's results.csv: {len(raw)} cells where the header has {len(fields)}",
                file=path,
                line=line,
            )
        row: dict[str, Any] = dict(zip(fields, raw, strict=True))
        for key in axes:
            row[key] = _number_or_text(row[key])
        for key in metrics:
            try:
                value = float(row[key]) if row[key] else None
                row[key] = value if value is not None and math.isfinite(value) else None
            except ValueError:
                raise ConfigError(
                    f"not a sweep's results.csv: {key} is {short_repr(row[key])}, not a number",
                    file=path,
                    line=line,
                ) from None
        rows.append(row)
    return rows, axes


def open_results(path: Path) -> IO[str]:
    """``path`` opened as UTF-8 text for a streamed read, if it is a regular file of at most
    :data:`MAX_RESULTS_BYTES` (else one line, as :func:`read_regular_file` says it).

    Opened without blocking and judged through the descriptor, so a FIFO planted as
    results.csv is refused rather than waited on; read it with :func:`bounded_lines`.
    """
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise ConfigError("file not found", file=path) from None
    except OSError as exc:
        raise ConfigError(f"cannot read: {exc.strerror}", file=path) from None
    try:
        st = os.fstat(fd)
        if stat.S_ISREG(st.st_mode) and st.st_size <= MAX_RESULTS_BYTES:
            return open(fd, encoding="utf-8", newline="", closefd=True)
    except OSError as exc:
        os.close(fd)
        raise ConfigError(f"cannot read: {exc.strerror}", file=path) from None
    os.close(fd)
    # not a regular file, or too large: the project's one check says which, in its words
    # (it opens without blocking and reads nothing of such a file)
    read_regular_file(Path(path), MAX_RESULTS_BYTES, EXPECTED)
    raise ConfigError(f"changed while opened, expected {EXPECTED}", file=path)


def bounded_lines(handle: IO[str], path: Path) -> Iterator[str]:
    """The lines of ``handle``, none longer than :data:`MAX_LINE_CHARS` and at most
    :data:`MAX_RESULTS_BYTES` characters in all (a file that grows while read is cut off
    there): a reader's memory never holds more than one line, whatever the file holds."""
    total = 0
    while True:
        line = handle.readline(MAX_LINE_CHARS + 1)
        if not line:
            return
        if len(line) > MAX_LINE_CHARS:
            raise ConfigError(
                f"not a results.csv: a line longer than {MAX_LINE_CHARS // 1024} KiB", file=path
            )
        total += len(line)
        if total > MAX_RESULTS_BYTES:
            raise ConfigError(
                f"file too large (more than {MAX_RESULTS_BYTES >> 20} MiB read)", file=path
            )
        yield line


def _number_or_text(text: str) -> Any:
    try:
        return float(text)
    except ValueError:
        return text
