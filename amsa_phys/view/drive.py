"""Advancing a simulation while stopping at frame times (no pygame: imported by every run)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction
from typing import Protocol

from ..engine.face import SimDriver, SimView


class FrameSink(Protocol):
    """Something that wants a picture at given simulated times (the recorder)."""

    def next_time(self) -> Fraction | None:
        """Simulated time of the next picture, or None when done."""

    def capture(self) -> None:
        """Take the picture of the simulation's current state."""


def last_tick_at(sim: SimView, t: Fraction) -> int:
    """The last instant at or before ``t`` on the simulation's grid."""
    return math.floor(t / sim.grid.tick)


def advance(sim: SimDriver, until_tick: int, sinks: Sequence[FrameSink] = ()) -> None:
    """``sim.advance(until_tick)``, stopping at every frame time on the way to capture it.

    Frame *k* shows the world after every instant *at or before* its time has run: the
    components due at a frame's instant have run, so its HUD shows the sample ``trace.csv``
    has at that time (it showed the one before: 21.42 m at 130.00 s where the trace says
    21.14 m). Several sinks (a video and a snapshot) are served in time order.
    """
    while sinks:
        due = [(t, i) for i, s in enumerate(sinks) if (t := s.next_time()) is not None]
        if not due:
            break
        t, i = min(due)
        tick = last_tick_at(sim, t)
        if tick > until_tick:
            break
        sim.advance(tick)
        sinks[i].capture()
    sim.advance(until_tick)
