"""The delivery heap: publications of Leaves with latency or jitter, in flight until due.

A delayed Leaf's outputs are not visible when it publishes them: its delay line
(``engine/timing.py``) says at which tick they arrive, and until then they wait here. The
engine delivers everything due at the start of an instant, before the timeline's changes
and the components (``Simulation._apply_instant``), so a reader due at that instant sees
them. Two publications due at one tick arrive in the order they were sent. A publication is
a list of (buffer, value) pairs, the buffer by its position in the store's array
(``store.py``; a test may use names and a dict alike).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import MutableMapping
from heapq import heappop
from typing import Any

import numpy as np


class Deliveries:
    """Publications in flight: (due tick, sequence number, [(buffer, value), ...])."""

    def __init__(self) -> None:
        self._heap: list[tuple[int, int, list[tuple[Any, float]]]] = []
        self._sent = 0

    def __bool__(self) -> bool:
        return bool(self._heap)

    def push(self, due: int, writes: list[tuple[Any, float]]) -> None:
        """Put ``writes`` in flight, visible from tick ``due``."""
        self._sent += 1
        heapq.heappush(self._heap, (due, self._sent, writes))

    def next_due(self) -> float:
        """The tick of the earliest publication in flight (``math.inf``: none)."""
        return self._heap[0][0] if self._heap else math.inf

    def deliver(
        self, tick: int, values: MutableMapping[Any, float] | Any, col: np.ndarray | None = None
    ) -> float:
        """Write every publication due at or before ``tick`` into ``values`` (the store's
        array), in order; return the tick the next one is due (``math.inf``: none), as
        :meth:`next_due`. A group's publication is whole columns, ``(positions, array)``
        with positions a slice or an index array, written through ``col`` (the store's
        numpy view) in one call."""
        heap = self._heap
        while heap and heap[0][0] <= tick:
            for at, value in heappop(heap)[2]:  # a position first: a single run's every write
                if type(at) is int or col is None:
                    values[at] = value
                else:
                    col[at] = value
        return heap[0][0] if heap else math.inf

    def in_flight(self, buffer: Any) -> int:
        """How many publications of ``buffer`` are sent but not yet visible."""
        return sum(
            1
            for _, _, writes in self._heap
            for at, _ in writes
            if (at == buffer if type(at) is not slice and np.ndim(at) == 0 else _holds(at, buffer))
        )


def _holds(at: slice | np.ndarray, position: Any) -> bool:
    """Whether a column write to ``at`` writes ``position``."""
    if type(at) is slice:
        return type(position) is int and position in range(at.start, at.stop, at.step or 1)
    return bool((at == position).any())
