"""The delivery heap: publications of Leaves with latency or jitter, in flight until due.

A delayed Leaf's outputs are not visible when it publishes them: its delay line
(``engine/timing.py``) says at which tick they arrive, and until then they wait here. The
engine delivers everything due at the start of an instant, before the timeline's changes
and the components (``Simulation._apply_instant``), so a reader due at that instant sees
them. Two publications due at one tick arrive in the order they were sent.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import MutableMapping


class Deliveries:
    """Publications in flight: (due tick, sequence number, [(buffer, value), ...])."""

    def __init__(self) -> None:
        self._heap: list[tuple[int, int, list[tuple[str, float]]]] = []
        self._sent = 0

    def __bool__(self) -> bool:
        return bool(self._heap)

    def push(self, due: int, writes: list[tuple[str, float]]) -> None:
        """Put ``writes`` in flight, visible from tick ``due``."""
        self._sent += 1
        heapq.heappush(self._heap, (due, self._sent, writes))

    def next_due(self) -> float:
        """The tick of the earliest publication in flight (``math.inf``: none)."""
        return self._heap[0][0] if self._heap else math.inf

    def deliver(self, tick: int, values: MutableMapping[str, float]) -> float:
        """Write every publication due at or before ``tick`` into ``values``, in order;
        return the tick the next one is due (``math.inf``: none), as :meth:`next_due`."""
        heap = self._heap
        while heap and heap[0][0] <= tick:
            values.update(heapq.heappop(heap)[2])
        return heap[0][0] if heap else math.inf

    def in_flight(self, buffer: str) -> int:
        """How many publications of ``buffer`` are sent but not yet visible."""
        return sum(1 for _, _, writes in self._heap for b, _ in writes if b == buffer)
