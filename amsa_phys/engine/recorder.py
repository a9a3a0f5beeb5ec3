"""The trace: every Data buffer at the log rate, streamed to a temporary file and renamed.

A run that is killed never leaves a half-written ``trace.csv``: rows go to
``trace.csv.tmp`` and ``os.replace`` gives it its final name only when the run is finalised
(normally, on a fault or on Ctrl-C). Floats are written with ``repr`` (shortest exact
round-trip), so the same run gives byte-identical files.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from itertools import compress
from operator import is_not
from pathlib import Path
from typing import IO

#: Rows collected before one write to the file.
_CHUNK = 128


class TraceWriter:
    """Streams trace rows to ``path`` atomically.

    Most buffers change at a lower rate than the log (a 4 Hz sensor in a 20 Hz trace), and
    ``repr`` of a float costs ~0.3 µs, so the writer keeps the last value *object* of each
    column with its text and formats only the columns holding a new object (found in C with
    ``map``/``compress``). Floats are immutable: the same object always has the same text,
    and identity keeps ``-0.0`` and ``0.0`` apart. Rows reach the file a chunk at a time.
    """

    def __init__(self, path: Path, columns: Sequence[str]) -> None:
        self.path = Path(path)
        self.tmp = self.path.with_name(self.path.name + ".tmp")
        self.columns = list(columns)
        self._fh: IO[str] | None = open(self.tmp, "w", encoding="utf-8", newline="\n")  # noqa: SIM115
        self._fh.write(",".join(["t", *self.columns]) + "\n")
        self.rows = 0
        self._last: list[object] = [None] * len(self.columns)
        self._text: list[str] = [""] * len(self.columns)
        self._index = range(len(self.columns))
        self._rows: list[str] = []  # formatted rows not yet written

    def write(self, t_s: float, values: Sequence[float]) -> None:
        """Append one row (``t`` in seconds, then one value per column)."""
        assert self._fh is not None, "trace already closed"
        last = self._last
        text = self._text
        for i in compress(self._index, map(is_not, values, last)):
            v = values[i]
            last[i] = v
            text[i] = repr(v)
        rows = self._rows
        rows.append(repr(t_s) + "," + ",".join(text) + "\n")
        self.rows += 1
        if len(rows) >= _CHUNK:
            self._flush_rows()

    def _flush_rows(self) -> None:
        """Hand the collected rows to the file in one call (a write per row costs ~2 µs)."""
        if self._rows and self._fh is not None:
            self._fh.write("".join(self._rows))
            self._rows.clear()

    def close(self) -> Path:
        """Flush, fsync and rename to the final name; safe to call twice."""
        if self._fh is not None:
            self._flush_rows()
            self._fh.flush()
            os.fsync(self._fh.fileno())
            self._fh.close()
            self._fh = None
            os.replace(self.tmp, self.path)
        return self.path


def write_atomic(path: Path, data: str | bytes) -> None:
    """Write a whole file under a temporary name, then rename it into place."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    mode = "wb" if isinstance(data, bytes) else "w"
    with open(tmp, mode) as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)
