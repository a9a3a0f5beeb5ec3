"""A run's ``trace.csv`` read in bounded memory, judged row by row: what ``plot`` and ``view``
draw from.

A maximum-length run writes gigabytes of trace (the tool warns of 9.4 GB), and a trace from
elsewhere may be anything, so the file is never held whole: it is read in blocks of
:data:`BLOCK_BYTES`, every row judged (as wide as the header, every cell a number, ``t``
finite, within the run-length limit and never going back), and only every ``stride``-th row
kept (plus the last), so that at most about :data:`MAX_CELLS` values stay in memory whatever
the file's size. A picture a few thousand pixels wide cannot show more rows than that anyway,
and the kept rows are the trace's own, never averaged: what is drawn is what the run wrote.
Peak memory is a few blocks plus the kept values (tests/runs/test_trace_memory.py).
A top-level module because both ``plots`` and ``view`` (through ``cli``) read traces and the
layers below ``runs`` may not import it.
"""

from __future__ import annotations

import io
import math
import os
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from ..errors import ConfigError, one_line
from ..model.params import short_repr
from ..model.schema import MAX_DURATION_S

#: bytes read at a time
BLOCK_BYTES = 4 << 20
#: the longest line taken for a row or the header (a 200-rover header is ~90 kB)
MAX_LINE_BYTES = 16 << 20
#: values kept for drawing (float64: 32 MiB); a longer trace keeps every k-th row
MAX_CELLS = 4_000_000
#: rows kept at least, however wide the trace
MIN_ROWS = 2_000


def read_header(path: Path) -> list[str]:
    """The header's column names; one line if the file is not a trace."""
    with open(path, "rb") as fh:
        head = fh.readline(MAX_LINE_BYTES + 1)
    if len(head) > MAX_LINE_BYTES:
        raise ConfigError("not a trace: its first line is longer than 16 MiB", file=path, line=1)
    try:
        header = head.decode("utf-8").rstrip("\n").split(",")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"not a trace: not UTF-8 text (byte {exc.start})", file=path) from None
    if header[0] != "t":
        raise ConfigError("not a whole trace: no header line starting with t", file=path, line=1)
    seen: set[str] = set()
    for name in header:  # which of two ``a`` columns would a formula or a plot read?
        if name in seen:
            raise ConfigError(
                f"not a trace: the column {one_line(name)!r} is named twice", file=path, line=1
            )
        seen.add(name)
    return header


def count_rows(path: Path) -> int:
    """Lines after the header (read in blocks)."""
    with open(path, "rb") as fh:
        n = sum(block.count(b"\n") for block in iter(lambda: fh.read(BLOCK_BYTES), b""))
    return max(0, n - 1)


def read_rows(
    path: Path, keep: frozenset[str] | None = None, max_cells: int = MAX_CELLS
) -> tuple[list[str], np.ndarray, int]:
    """The trace's column names (``t`` and ``keep``'s, or all), its kept rows and the
    stride (1: every row). Refuses, with one line naming file and line, anything that is not
    a whole trace. Values are as written (NaN, inf and 1e300 included)."""
    header = read_header(path)
    size = os.path.getsize(path)
    if size:
        with open(path, "rb") as fh:
            fh.seek(-1, os.SEEK_END)
            if fh.read(1) != b"\n":  # a row cut short, as a killed writer would leave it
                line = count_rows(path) + 2
                raise ConfigError("not a whole trace: cut short", file=path, line=line)
    cols = [i for i, name in enumerate(header) if i == 0 or keep is None or name in keep]
    names = [header[i] for i in cols]
    rows = count_rows(path)
    stride = max(1, math.ceil(rows / max(MIN_ROWS, max_cells // max(1, len(cols)))))
    parts: list[np.ndarray] = []
    last_t = -math.inf
    first = 0  # data row index of the block's first row
    last_row: np.ndarray | None = None
    for block in _blocks(path):
        data = _parse(path, block, len(header), cols, first)
        if len(data):
            _judge_times(path, data[:, 0], first, last_t)
            last_t = float(data[-1, 0])
            offset = (-first) % stride
            parts.append(data[offset::stride].copy())
            last_row = data[-1:].copy()
        first += len(data)
    if last_row is not None and (first - 1) % stride:
        parts.append(last_row)  # the run's end, whatever the stride
    out = np.concatenate(parts) if parts else np.empty((0, len(cols)))
    return names, out, stride


def _blocks(path: Path) -> Iterator[bytes]:
    """The file after its header, as blocks of whole lines."""
    with open(path, "rb") as fh:
        fh.readline(MAX_LINE_BYTES + 1)
        carry = b""
        line = 2
        while True:
            chunk = fh.read(BLOCK_BYTES)
            if not chunk:
                break
            data = carry + chunk
            cut = data.rfind(b"\n") + 1
            carry = data[cut:]
            if len(carry) > MAX_LINE_BYTES:
                raise ConfigError(
                    "not a whole trace: a row longer than 16 MiB", file=path, line=line
                )
            if cut:
                block = data[:cut]
                line += block.count(b"\n")
                yield block


def _parse(path: Path, block: bytes, width: int, cols: Sequence[int], first: int) -> np.ndarray:
    """One block's rows, the kept columns, every row checked to be ``width`` numbers."""
    raw = np.frombuffer(block, dtype=np.uint8)
    ends = np.flatnonzero(raw == 10)
    commas = np.flatnonzero(raw == 44)
    per_line = np.diff(np.searchsorted(commas, ends), prepend=0)
    wrong = np.flatnonzero(per_line != width - 1)
    try:
        if len(wrong):
            raise ValueError
        text = block.decode("utf-8")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            data = np.loadtxt(io.StringIO(text), delimiter=",", ndmin=2, usecols=cols)
    except (ValueError, UnicodeDecodeError):
        line, problem = _bad_row(block, width)
        raise ConfigError(
            f"not a whole trace: {problem}", file=path, line=first + 2 + line
        ) from None
    if data.shape != (len(ends), len(cols)):
        raise ConfigError("not a whole trace: unreadable", file=path, line=first + 2)
    return data


def _bad_row(block: bytes, width: int) -> tuple[int, str]:
    """The first line of ``block`` (from 0) that is not ``width`` numbers, and why."""
    for i, raw in enumerate(block.split(b"\n")):
        try:
            row = raw.decode("utf-8")
        except UnicodeDecodeError:
            return i, "not UTF-8 text"
        cells = row.split(",")
        if len(cells) != width:
            return i, f"{len(cells)} values where the header names {width}"
        for cell in cells:
            try:
                float(cell)
            except ValueError:
                return i, f"{short_repr(cell)} is not a number"
    return 0, "unreadable"


def _judge_times(path: Path, t: np.ndarray, first: int, before: float) -> None:
    why = time_problem(t, before)
    if why is not None:
        raise ConfigError(why[1], file=path, line=first + why[0] + 2)


def time_problem(t: np.ndarray, before: float = -math.inf) -> tuple[int, str] | None:
    """The first row of ``t`` whose time a run could not have written, and why: not finite,
    outside ``0..MAX_DURATION_S``, or before the row above it (``before`` for the first; the
    scrubber's binary search and every plot's time axis rely on ``t`` rising)."""
    bad = ~np.isfinite(t)
    if bad.any():
        i = int(np.argmax(bad))
        return i, f"t is not a finite time ({t[i]})"
    out = (t < 0) | (t > MAX_DURATION_S)
    if out.any():
        i = int(np.argmax(out))
        return i, f"t is outside 0..{MAX_DURATION_S:,} s ({t[i]:g})"
    back = np.diff(t, prepend=before) < 0
    if back.any():
        i = int(np.argmax(back))
        previous = t[i - 1] if i else before
        return i, f"t goes backwards ({t[i]:g} after {previous:g})"
    return None
