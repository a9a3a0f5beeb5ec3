"""What the engine hands out: a component's context, the events of a run, its result.

Kept apart from the loop (``runner.py``) so templates and reports can name these types
without reading the engine's facade.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction
from typing import TYPE_CHECKING, Any

import numpy as np

from .rng import component_rng

if TYPE_CHECKING:
    from .runner import Simulation

Hook = Callable[[], None]


@dataclass
class Event:
    """Something that happened during the run (a collision, ...), at simulated time ``t``."""

    t: float
    kind: str
    detail: str


class Context:
    """What a component's ``initialize`` receives.

    ``rng`` is the component's own stream. ``shared`` returns a per-run service created on
    first request (the physics world), so templates in different layers can meet without
    importing each other's modules. ``add_hook`` registers a subsystem step at its own rate.
    """

    def __init__(self, sim: Simulation, path: str, run: int = 0) -> None:
        self._sim = sim
        self.path = path
        #: the run of a batch the component belongs to (``multirun.py``); 0 alone
        self.run = run
        self.world = sim.world

    def __getattr__(self, name: str) -> Any:
        """``rng``, made at its first use: the stream depends on the seed and the path
        alone, so it is the same whenever it is made, and a component that draws nothing
        (a robot, a monitor, an actuator) costs no Generator (a Gymnasium reset makes every
        component's context again)."""
        if name == "rng":
            self.rng = rng = component_rng(self._sim.seed, self.path)
            return rng
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def shared(self, name: str, factory: Callable[[Simulation], Any]) -> Any:
        """The run's shared service ``name``, created by ``factory(sim)`` the first time."""
        if name not in self._sim.shared:
            self._sim.shared[name] = factory(self._sim)
        return self._sim.shared[name]

    def add_hook(self, rate_hz: Fraction, fn: Hook, name: str) -> None:
        """Call ``fn()`` at ``rate_hz`` after the components due at the same instant."""
        self._sim.add_hook(rate_hz, fn, name)

    def record_event(self, kind: str, detail: str) -> None:
        """Record an event at the current simulated time."""
        self._sim.record_event(kind, detail)


@dataclass
class RunResult:
    """What a finished (or interrupted) run produced, for metrics and reports."""

    t_end: float
    samples_t: np.ndarray
    samples_s: np.ndarray
    events: list[Event] = field(default_factory=list)
    #: the STL requirements' entries of ``metrics.json`` (``stl/requirement.py``),
    #: when the run's requirements were judged with its samples; None: no requirement
    requirements: dict[str, Any] | None = None
    #: every ``adapt:`` switch of the run (``events`` keeps only the first ones)
    adapt_switches: int = 0
