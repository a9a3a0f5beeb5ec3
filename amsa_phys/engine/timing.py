"""Loop timing in the engine: the phase of each Leaf's timer and its outputs' delay line.

``model/timing.py`` says what ``latency``, ``jitter`` and ``phase`` mean. Here they become
integers on the run's tick grid:

* a phase shifts the Leaf's instants in the schedule table (so it must lie on the grid: the
  engine adds every phase to the grid's instants; random phases are drawn on the world's
  ``timing.resolution`` for that reason);
* a delay line turns "published at tick n" into "visible from tick d": ``d`` is the first
  tick at or after ``n + latency + u * jitter``, never ``n`` itself, never before the
  previous message's (messages of one Leaf stay in order). A delivery between two instants
  is applied at the next instant anything runs, which no reader can tell apart. Latency and
  jitter therefore need not lie on the grid, and a delay line costs nothing per physics step.

Random draws come from streams of their own (``rng.named_rng``: ``"phase"``, ``"jitter"``),
so timing never changes a component's random numbers, and a world without random timing
draws nothing at all.
"""

from __future__ import annotations

import math
from fractions import Fraction

from ..model.timing import RANDOM, resolution
from ..model.world import LeafSpec, WorldSpec
from .rng import Drawn, named_rng


def leaf_phase(leaf: LeafSpec, world: WorldSpec, seed: int) -> Fraction:
    """The phase of ``leaf``'s timer in this run (drawn for a random one)."""
    phase = leaf.timing.phase
    if phase is None:
        phase = RANDOM if world.free_running else Fraction(0)
    if phase != RANDOM:
        return Fraction(phase)
    period = 1 / leaf.freq
    res = resolution(world.timing)
    steps = max(1, math.floor(period / res))  # phases k * res, all below the period
    u = float(named_rng(seed, leaf.path, "phase").random())
    return min(steps - 1, math.floor(u * steps)) * res


def run_phases(world: WorldSpec, seed: int) -> dict[str, Fraction]:
    """Every Leaf's phase in a run with ``seed``."""
    return {path: leaf_phase(leaf, world, seed) for path, leaf in world.leaves.items()}


class DelayLine:
    """When a Leaf's publications become visible to its readers."""

    def __init__(self, leaf: LeafSpec, tick: Fraction, seed: int) -> None:
        t = leaf.timing
        self.tick = tick
        self.latency = t.latency
        self.jitter = t.jitter
        #: whole ticks of the fixed latency, rounded up (at least one: never the same instant)
        self.fixed = max(1, math.ceil(t.latency / tick))
        self.draw = Drawn(named_rng(seed, leaf.path, "jitter").random) if t.jitter else None
        self.last = 0

    def due(self, tick: int) -> int:
        """The tick from which a message published at ``tick`` is visible."""
        if self.draw is None:
            due = tick + self.fixed
        else:
            delay = self.latency + Fraction(self.draw()) * self.jitter
            due = tick + max(1, math.ceil(delay / self.tick))
        if due < self.last:
            due = self.last
        self.last = due
        return due
