"""The run's log: trace rows, quality samples and log listeners at every logged instant.

At each instant the schedule marks for logging (``log_rate``), the log writes one trace row
(the chosen columns, in order, gathered in C by ``itemgetter``), appends the quality
signal's sample, then calls the listeners (the window's trails, live metrics) with the same
values: the very samples ``metrics.json`` is computed from, whatever the frame rate.
"""

from __future__ import annotations

import operator
from array import array
from collections.abc import Callable, Sequence

import numpy as np

Listener = Callable[[float, dict[str, float]], None]


class RunLog:
    """Trace, quality samples and listeners of one run (see the module docstring)."""

    def __init__(
        self,
        columns: Sequence[str],
        trace: Callable[[float, list[float]], None] | None,
        quality: str | None,
    ) -> None:
        self.columns = list(columns)
        self._trace = trace
        self._quality = quality
        # quality samples as packed doubles: a 1-hour run logs 72,000 of each, 1 MiB as
        # arrays instead of ~5 MiB of float objects in lists
        self._samples_t = array("d")
        self._samples_s = array("d")
        self.listeners: list[Listener] = []
        cols = self.columns
        #: one row of the trace in column order, gathered in C
        self.row: Callable[[dict[str, float]], Sequence[float]] = (
            operator.itemgetter(*cols) if len(cols) > 1 else lambda v: [v[c] for c in cols]
        )

    def record(self, t_s: float, values: dict[str, float]) -> None:
        """Log the instant at ``t_s`` seconds: trace row, quality sample, listeners."""
        if self._trace is not None:
            self._trace(t_s, self.row(values))  # type: ignore[arg-type]
        if self._quality is not None:
            self._samples_t.append(t_s)
            self._samples_s.append(values[self._quality])
        if self.listeners:
            for listener in self.listeners:
                listener(t_s, values)

    def samples(self) -> tuple[np.ndarray, np.ndarray]:
        """The quality samples so far: (times, values), of equal length."""
        # equal lengths even if a second Ctrl-C (raised at once) fell between the two appends
        n = min(len(self._samples_t), len(self._samples_s))
        return (
            np.array(self._samples_t[:n], dtype=np.float64),
            np.array(self._samples_s[:n], dtype=np.float64),
        )
