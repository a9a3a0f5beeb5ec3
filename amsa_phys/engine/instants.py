"""Changes applied at an exact instant: the timeline's, and any other source's (rules).

The engine applies instant-level changes at one point of its loop
(``Simulation._apply_instant``), before the components due at that instant: first the
delayed publications that arrive then, then each :class:`InstantSource` in the order they
were added — the timeline first — then live changes made by hand. The hot loop compares the
tick with one number only, the earliest tick any of them has something due at.

A source is anything with ``next_tick()`` (the next tick it has changes for, ``math.inf``
if none) and ``due(tick)`` (the batches due at or before ``tick``, each ``(at, phase,
changes)``: ``at`` the tick the changes are for — the time they are logged at, even if the
loop first runs at a later tick — and ``phase`` the phase they belong to, or None to stay in
the current one).
Adaptation rules plug in here with
:meth:`Simulation.add_instant_source`, and land exactly where a timeline entry at that
instant would.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Protocol

from ..model.scenario import Change
from ..model.timeline import Timeline
from .clock import TickGrid

Batch = tuple[int, int | None, Sequence[Change]]


class InstantSource(Protocol):
    """Something that changes parameters at exact instants (see the module docstring)."""

    def next_tick(self) -> float:
        """The next tick this source has changes for (``math.inf``: none)."""
        ...

    def due(self, tick: int) -> list[Batch]:
        """The batches due at or before ``tick``, in order; they are then consumed."""
        ...


class TimelineSource:
    """The timeline's points after t = 0 as an instant source, on the run's tick grid.

    ``run`` is the run of a batch whose components the changes are for (``multirun.py``);
    a source without that attribute changes run 0, the single run.
    """

    def __init__(self, timeline: Timeline, grid: TickGrid, run: int = 0) -> None:
        self._points: list[Batch] = [
            (grid.ticks(p.at), p.phase, p.changes) for p in timeline.points()
        ]
        self._i = 0
        self.run = run

    def next_tick(self) -> float:
        """See :meth:`InstantSource.next_tick`."""
        return self._points[self._i][0] if self._i < len(self._points) else math.inf

    def due(self, tick: int) -> list[Batch]:
        """See :meth:`InstantSource.due` (a step inside a phase names its phase too)."""
        out: list[Batch] = []
        points = self._points
        while self._i < len(points) and points[self._i][0] <= tick:
            out.append(points[self._i])
            self._i += 1
        return out
