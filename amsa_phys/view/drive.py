"""Advancing a simulation while stopping at frame times (no pygame: imported by every run)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction
from typing import Protocol

from ..engine.runner import Simulation


class FrameSink(Protocol):
    """Something that wants a picture at given simulated times (the recorder)."""

    def next_time(self) -> Fraction | None:
        """Simulated time of the next picture, or None when done."""

    def capture(self) -> None:
        """Take the picture of the simulation's current state."""


def last_tick_before(sim: Simulation, t: Fraction) -> int:
    """The last instant strictly before ``t`` on the simulation's grid."""
    return math.ceil(t / sim.grid.tick) - 1


def advance(sim: Simulation, until_tick: int, sinks: Sequence[FrameSink] = ()) -> None:
    """``sim.advance(until_tick)``, stopping at every frame time on the way to capture it.

    Frame *k* shows the world after every instant before its time has run. Several sinks
    (a video and a snapshot) are served in time order.
    """
    while sinks:
        due = [(t, i) for i, s in enumerate(sinks) if (t := s.next_time()) is not None]
        if not due:
            break
        t, i = min(due)
        tick = last_tick_before(sim, t)
        if tick > until_tick:
            break
        sim.advance(tick)
        sinks[i].capture()
    sim.advance(until_tick)
