"""The run's log: trace rows, quality samples and log listeners at every logged instant.

At each instant the schedule marks for logging (``log_rate``), the log writes one trace row
(the chosen columns, in order, gathered in C by ``itemgetter`` from the store's array),
appends the quality signal's sample, then calls the listeners (the window's trails, live
metrics) with the same values by name: the very samples ``metrics.json`` is computed from,
whatever the frame rate.
"""

from __future__ import annotations

import operator
from array import array
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

Listener = Callable[[float, Mapping[str, float]], None]


class RunLog:
    """Trace, quality samples and listeners of one run (see the module docstring).

    ``at(name)`` is a buffer's position in the store's array (identity for a dict by
    name); ``named`` is the same values by name, what listeners receive; ``col`` the store's
    numpy view, from which a writer with ``packed_rows`` takes its rows.
    """

    def __init__(
        self,
        columns: Sequence[str],
        trace: Callable[[float, list[float]], None] | None,
        quality: str | None,
        at: Callable[[str], Any] = lambda name: name,
        named: Mapping[str, float] | None = None,
        col: np.ndarray | None = None,
    ) -> None:
        self.columns = list(columns)
        self.named = named
        self._trace = trace
        #: whether a trace writer takes the rows
        self.has_trace = trace is not None
        self._quality = None if quality is None else at(quality)
        # quality samples as packed doubles: a 1-hour run logs 72,000 of each, 1 MiB as
        # arrays instead of ~5 MiB of float objects in lists
        self._samples_t = array("d")
        self._samples_s = array("d")
        #: True while the quality signal holds no measurement yet (its port's initial value
        #: until a free-mode ROS node's first message): no sample is taken, so the metrics
        #: never count a value nothing measured. The run's owner clears it.
        self.quality_waits = False
        self.listeners: list[Listener] = []
        cols = [at(c) for c in self.columns]
        #: one row of the trace in column order, gathered in C
        self.row: Callable[[Any], Sequence[float]] = (
            operator.itemgetter(*cols) if len(cols) > 1 else lambda v: [v[c] for c in cols]
        )
        if col is not None and getattr(trace, "packed_rows", False):
            # a writer that stores packed doubles (``tracemem.py``) takes the row as one
            # float64 array: copied from the store's array in C, no float object per value
            where = np.array(cols, dtype=np.intp)
            take = col.take
            self.row = lambda _values: take(where)
        #: rows gathered a block at a time for a writer that takes blocks (:class:`RowBlock`)
        self._block: RowBlock | None = None
        owner = getattr(trace, "__self__", None)
        blocks = getattr(trace, "packed_rows", False) and hasattr(owner, "write_block")
        small = col is not None and (col.size <= RowBlock.MAX_STORE or col.size <= 4 * len(cols))
        if blocks and small:
            assert col is not None
            self._block = RowBlock(col, np.array(cols, dtype=np.intp), owner.write_block)
            owner.pending = self._block.flush

    def record(self, t_s: float, values: Any) -> None:
        """Log the instant at ``t_s`` seconds from ``values`` (the store's array): trace
        row, quality sample, listeners (given the values by name)."""
        if self._block is not None:
            self._block.add(t_s)
        elif self._trace is not None:
            self._trace(t_s, self.row(values))  # type: ignore[arg-type]
        if self._quality is not None and not self.quality_waits:
            self._samples_t.append(t_s)
            self._samples_s.append(values[self._quality])
        if self.listeners:
            named = values if self.named is None else self.named
            for listener in self.listeners:
                listener(t_s, named)

    def samples(self) -> tuple[np.ndarray, np.ndarray]:
        """The quality samples so far: (times, values), of equal length."""
        # equal lengths even if a second Ctrl-C (raised at once) fell between the two appends
        n = min(len(self._samples_t), len(self._samples_s))
        return (
            np.array(self._samples_t[:n], dtype=np.float64),
            np.array(self._samples_s[:n], dtype=np.float64),
        )


class RowBlock:
    """Trace rows a block at a time, for a writer with ``write_block`` (``tracemem.py``).

    At each logged instant the whole store's array is copied into the next row of a block
    (one memcpy: a third of gathering the traced columns into a row of their own and
    appending its bytes); a full block, or the writer before any read (its ``pending``),
    takes the traced columns of every row in one numpy call. The same doubles, in the same
    order: only when they are copied changes. Used where the store is at most a few times
    the traced columns (a copy of a large store for a few columns would cost more).
    """

    SIZE = 512
    #: a store up to this many values is copied whole whatever the traced columns
    MAX_STORE = 4096

    def __init__(
        self, col: np.ndarray, where: np.ndarray, write_block: Callable[[Any, Any], None]
    ) -> None:
        self.col = col
        everything = len(where) == col.size and bool((where == np.arange(col.size)).all())
        self.where = None if everything else where
        self.rows = np.empty((self.SIZE, col.size), dtype=np.float64)
        self.times = array("d")
        self.write_block = write_block

    def add(self, t_s: float) -> None:
        """Take the store's values now as the row at ``t_s``."""
        times = self.times
        self.rows[len(times)] = self.col
        times.append(t_s)
        if len(times) == self.SIZE:
            self.flush()

    def flush(self) -> None:
        """Hand the rows taken so far to the writer."""
        n = len(self.times)
        if n:
            rows = self.rows[:n] if self.where is None else self.rows[:n, self.where]
            self.write_block(np.frombuffer(self.times, dtype=np.float64), rows)
            self.times = array("d")
