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
    if b"e" in body or b".0000" in body:
        body = _respell(body)
    return body + b"\n"


def _respell(body: bytes) -> bytes:
    """Re-spell with ``repr`` the numbers of ``body`` whose orjson spelling may differ.

    Only the numbers holding an ``e`` or a ``.0000`` are touched, found with ``bytes.find``
    (memchr speed) and widened to their commas. The first version split every line holding
    such a number into its tokens in Python: in a 200-car platoon nearly every 60 KB row
    holds one (a stopped car's speed is ``1e-7``-small), so re-spelling took ~0.3 s of a
    256-row chunk, ~40 % of the run, growing as cars stopped (the real-time
    factor fell from 12.7 to 8.4 over ten minutes). A regular expression was no better:
    ``re`` scans 15 MB at ~30 MB/s. Here a chunk with 2,500 such numbers takes ~10 ms.
    """
    spans: set[tuple[int, int]] = set()
    n = len(body)
    for needle in (b"e", b".0000"):
        i = body.find(needle)
        while i != -1:
            start = max(body.rfind(b",", 0, i), body.rfind(b"\n", 0, i)) + 1
            comma, newline = body.find(b",", i), body.find(b"\n", i)
            end = min(comma if comma != -1 else n, newline if newline != -1 else n)
            spans.add((start, end))
            i = body.find(needle, end)
    if not spans:
        return body
    parts: list[bytes] = []
    at = 0
    for start, end in sorted(spans):
        parts.append(body[at:start])
        parts.append(repr(float(body[start:end])).encode())
        at = end
    parts.append(body[at:])
    return b"".join(parts)


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
