"""A sliding time window of samples, shared by the context estimators."""

from __future__ import annotations

from collections import deque
from typing import Generic, TypeVar

T = TypeVar("T")


class Window(Generic[T]):
    """Samples of the last ``span_s`` seconds, oldest first (``t`` in seconds).

    A sample at exactly ``now - span_s`` is kept, so a window of 30 s at 4 Hz holds 121
    samples once full: the count a reader computing the noise by hand expects.
    """

    def __init__(self, span_s: float) -> None:
        self.span_s = span_s
        self.items: deque[tuple[float, T]] = deque()

    def add(self, t: float, item: T) -> None:
        """Append a sample and drop the ones older than the window."""
        self.items.append((t, item))
        limit = t - self.span_s
        items = self.items
        while items and items[0][0] < limit:
            items.popleft()

    def __len__(self) -> int:
        return len(self.items)

    def covered_s(self) -> float:
        """Seconds between the oldest and newest sample (0 with fewer than two)."""
        if len(self.items) < 2:
            return 0.0
        return self.items[-1][0] - self.items[0][0]
