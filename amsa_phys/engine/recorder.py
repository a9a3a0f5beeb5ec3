"""The trace: every Data buffer at the log rate, streamed to a temporary file and renamed.

A run that is killed never leaves a half-written ``trace.csv``: rows go to
``trace.csv.tmp`` (``amsa_phys.atomic``) and it gets its final name only when the run is
finalised (normally, on a fault or on Ctrl-C). A write that fails (a full disk) raises
:class:`~amsa_phys.errors.OutputError` from the run loop and removes the temporary file.
Floats are spelled as ``repr`` spells them (shortest exact round-trip), so the same run gives
byte-identical files.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import orjson

from ..atomic import AtomicFile, write_atomic

__all__ = ["TraceWriter", "format_rows", "write_atomic"]

#: Rows collected before they are formatted and written in one go.
_CHUNK = 256


def format_rows(rows: Sequence[Sequence[float]]) -> bytes:
    """CSV lines for ``rows`` of floats, each float spelled exactly as ``repr`` spells it.

    ``repr`` of a float costs ~0.5 µs, a trace row holds ~25 of them, so formatting was a
    sixth of a headless run. orjson formats a whole chunk in C (~0.04 µs a float) with the
    same shortest round-trip digits; it spells some exponents differently (``1e-7`` for
    ``1e-07``, ``0.00001`` for ``1e-05``, and versions differ), so lines that may hold such
    a number (an ``e``, or ``0.0000``) are re-spelled with ``repr``. The file is therefore
    byte-identical to the plain ``repr`` one whatever the orjson version. NaN and infinity
    (orjson writes ``null``; the engine never logs them) also take the ``repr`` path.
    """
    if not rows:
        return b""
    blob = orjson.dumps(rows, default=float)
    if b"n" in blob:  # null: a non-finite value
        return "".join(",".join(map(repr, row)) + "\n" for row in rows).encode()
    body = blob[2:-2].replace(b"],[", b"\n")  # [[a,b],[c,d]] -> a,b\nc,d
    if b"e" in body or _tiny_positional(body):
        body = _respell(body)
    return body + b"\n"


def _tiny_positional(body: bytes) -> bool:
    """Whether a number of ``body`` is written ``0.0000...`` (repr writes ``1e-05``).

    Found through ``.0000`` and a look at the two bytes before it: CPython's search for
    ``0.0000`` itself is ~20x slower on digit-heavy text than for ``.0000``, and a wide
    trace holds a ``.0000`` in most rows (``12.00003``) but a tiny positional almost never.
    """
    find = body.find
    i = find(b".0000")
    while i != -1:
        if i >= 1 and body[i - 1] == 0x30 and (i == 1 or body[i - 2] in b",-\n"):
            return True
        i = find(b".0000", i + 5)
    return False


def _respell(body: bytes) -> bytes:
    """Re-spell with ``repr`` the numbers of ``body`` whose orjson spelling may differ."""
    lines = body.split(b"\n")
    for k, line in enumerate(lines):
        if b"e" in line or _tiny_positional(line):
            lines[k] = b",".join(
                repr(float(tok)).encode() if b"e" in tok or b"0.0000" in tok else tok
                for tok in line.split(b",")
            )
    return b"\n".join(lines)


class TraceWriter:
    """Streams trace rows to ``path`` atomically.

    Rows are kept as tuples and formatted a chunk at a time (:func:`format_rows`), so a row
    costs the run about a microsecond instead of ~8. Values must be floats (the engine's
    buffers hold nothing else).
    """

    def __init__(self, path: Path, columns: Sequence[str]) -> None:
        self.path = Path(path)
        self.columns = list(columns)
        self._file = AtomicFile(self.path)
        self.tmp = self._file.tmp
        self._file.write((",".join(["t", *self.columns]) + "\n").encode())
        self.rows = 0
        self._rows: list[tuple[float, ...]] = []  # rows not yet written
        self._closed = False

    @property
    def failed(self) -> bool:
        """Whether a write failed (the temporary file is gone; there will be no trace)."""
        return self._file.failed

    def write(self, t_s: float, values: Sequence[float]) -> None:
        """Append one row (``t`` in seconds, then one value per column)."""
        rows = self._rows
        rows.append((t_s, *values))
        self.rows += 1
        if len(rows) >= _CHUNK:
            self._flush_rows()

    def _flush_rows(self) -> None:
        """Format the collected rows and hand them to the file in one call."""
        if self._rows:
            data = format_rows(self._rows)
            self._rows.clear()
            self._file.write(data)

    def close(self) -> Path | None:
        """Flush, fsync and rename to the final name; safe to call twice.

        None if a write failed (the trace is lost, never left truncated).
        """
        if not self._closed:
            self._closed = True
            if not self._file.failed:
                self._flush_rows()
                self._file.commit()
        return None if self._file.failed else self.path

    def discard(self) -> None:
        """Drop the trace (its temporary file) without giving it its final name."""
        self._closed = True
        self._file.discard()
