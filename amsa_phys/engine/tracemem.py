"""The trace kept in memory (``amsa_phys.run``): rows as packed doubles, written on request.

A run from Python writes no file unless asked, so its rows go to one flat ``array('d')``
(8 bytes a value, no float objects: a 1-hour run of the MDE world is ~15 MiB) instead of a
file. :meth:`TraceMemory.save` replays them through the very :class:`TraceWriter` the CLI
streams to, so the saved ``trace.csv`` is byte-identical to ``amsa-phys run --headless``.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from .tracefile import TraceWriter


class TraceMemory:
    """Collects trace rows (``t``, then one value per Data buffer) in memory."""

    def __init__(self, columns: Sequence[str]) -> None:
        self.columns = list(columns)
        self.width = len(self.columns) + 1
        self._flat = array("d")
        self._closed = False
        #: set by the engine's log when it hands rows a block at a time (``log.py``'s
        #: ``RowBlock.flush``): called before any read, so the rows still in the block are
        #: here (reads come from the thread that runs the simulation)
        self.pending: Callable[[], None] | None = None

    def write(self, t_s: float, values: Sequence[float] | np.ndarray) -> None:
        """Append one row (the engine's trace callback): floats, or a float64 array, which
        the engine gives this writer (:attr:`packed_rows`) — its bytes are appended as they
        are, three times cheaper than boxing each value as a float and unboxing it here."""
        flat = self._flat
        flat.append(t_s)
        if type(values) is np.ndarray:
            flat.frombytes(values.tobytes())
        else:
            flat.extend(values)

    #: tells the engine's log (``log.py``) to hand :meth:`write` rows as float64 arrays
    write.packed_rows = True  # type: ignore[attr-defined]

    def write_block(self, times: np.ndarray, rows: np.ndarray) -> None:
        """Append ``len(times)`` rows at once: ``rows`` is ``(n, columns)`` float64, what
        ``n`` calls of :meth:`write` would append."""
        block = np.empty((len(times), self.width), dtype=np.float64)
        block[:, 0] = times
        block[:, 1:] = rows
        self._flat.frombytes(block.tobytes())

    def _drain(self) -> None:
        if self.pending is not None:
            self.pending()

    def close(self) -> None:
        """No more rows: the arrays handed out from now on are views, not copies."""
        self._drain()
        self._closed = True

    @property
    def rows(self) -> int:
        """Rows recorded so far."""
        self._drain()
        return len(self._flat) // self.width

    def matrix(self) -> np.ndarray:
        """The rows as a read-only ``(rows, 1 + columns)`` float64 array (``t`` first)."""
        self._drain()
        # a view while rows may still come would pin the array: ``extend`` then fails
        data = np.frombuffer(self._flat, dtype=np.float64) if self._closed else np.array(self._flat)
        data = data.reshape(-1, self.width)
        data.flags.writeable = False
        return data

    def structured(self) -> np.ndarray:
        """The rows as a structured array: ``trace["t"]``, ``trace["Follower.posX"]``, ..."""
        dtype = np.dtype([(name, np.float64) for name in ("t", *self.columns)])
        return self.matrix().view(dtype).reshape(-1)

    def save(self, path: Path) -> Path:
        """Write ``trace.csv`` exactly as the CLI writes it (same writer, atomically)."""
        writer = TraceWriter(path, self.columns)
        for row in self.matrix().tolist():  # on an error only ``trace.csv.tmp`` is left
            writer.write(row[0], row[1:])
        return writer.close()
