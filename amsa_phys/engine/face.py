"""What code outside the engine may touch of a running simulation: its faces.

``Simulation`` (``runner.py``) keeps fifty attributes, most of them the hot loop's own (the
instant table, the cursor, the delivery heap). The window, plots, Gymnasium renderer, bag,
reports and ROS runtimes read a run through these protocols instead, so the loop can change
its insides without breaking a reader, and a reader says by its type what it may do:

* :class:`SimView`: read a run (time, world, timeline and phase, the Data, events, live
  changes, log listeners). Nothing here changes what the run computes.
* :class:`SimDriver`: a :class:`SimView` that also runs it (initialize, advance, result),
  takes a change by hand or a write from another thread: ``runs/``, the window, a ROS
  runtime.
* :class:`ServiceHost`: what a run's shared service (the physics world) is given: the
  clock, hooks at a rate, events.
* :class:`BatchDriver`: a :class:`SimDriver` of a batch of runs (``multirun.py``).

``Simulation`` satisfies all but the last, ``MultiRun`` all four (a test checks it).
``tests/structure/test_sim_face.py`` fails when a module outside ``engine/`` reads an
attribute of a simulation that no face here declares.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

if TYPE_CHECKING:
    import numpy as np

    from ..model.scenario import Change
    from ..model.template import Template
    from ..model.timeline import Timeline
    from ..model.world import WorldSpec
    from .clock import TickGrid
    from .context import Event, Hook, RunResult

#: ``fn(t_s, values)`` at every logged instant, the values by buffer name
LogListener = Callable[[float, Mapping[str, float]], None]


@runtime_checkable
class SimView(Protocol):
    """A running simulation, read-only (see the module docstring)."""

    @property
    def world(self) -> WorldSpec:
        """The world the run steps (its first run's, in a batch)."""

    @property
    def timeline(self) -> Timeline:
        """The run's timeline: phases, changes, planned bounds."""

    @property
    def duration(self) -> Fraction:
        """When the run ends, in simulated seconds."""

    @property
    def now(self) -> Fraction:
        """Exact simulated time of the instant being executed (or last executed)."""

    @property
    def grid(self) -> TickGrid:
        """The run's tick grid (exists once initialized): time <-> ticks, exactly."""

    @property
    def phase_index(self) -> int:
        """The phase in force (index into ``timeline.phases``)."""

    @property
    def finished(self) -> bool:
        """Whether the run reached its duration."""

    @property
    def events(self) -> Sequence[Event]:
        """What happened so far (collisions, live changes, adapt switches, ...)."""

    @property
    def live_changes(self) -> Sequence[tuple[Fraction, Change]]:
        """The changes made by hand so far, each with the instant it landed at."""

    @property
    def pending_live(self) -> list[Change]:
        """Live changes queued for the next instant, not yet applied."""

    @property
    def components(self) -> Mapping[str, Template]:
        """The (first) run's components by path (their ``p`` holds the values in force)."""

    @property
    def columns(self) -> Sequence[str]:
        """The buffers of a trace row, in order."""

    @property
    def timer_phases(self) -> Mapping[str, Fraction]:
        """Each Leaf's timer phase (exists once initialized; 0 unless given or drawn)."""

    def service(self, name: str) -> Any:
        """The run's shared service ``name`` (``"physics"``: the physics world), or None."""

    def read(self, buffer: str, run: int = 0) -> float:
        """A buffer's value now."""

    def read_many(self, buffers: Sequence[str], run: int = 0) -> np.ndarray:
        """Several buffers' values now, in order."""

    def column(self, buffer: str) -> np.ndarray:
        """A buffer's value in every run of a batch."""

    def at(self, buffer: str, run: int = 0) -> int:
        """A buffer's position in :attr:`data` (a hot reader's index, looked up once)."""

    @property
    def data(self) -> Any:
        """Every buffer's value now, by :meth:`at` position; a reader's, never written."""

    def in_flight(self, buffer: str) -> int:
        """Publications of ``buffer`` sent but not yet visible (delayed Leaves)."""

    def next_instant(self) -> Fraction:
        """Time of the next instant at which something runs (where a live change lands)."""

    def add_log_listener(self, fn: LogListener) -> None:
        """Call ``fn(t_s, values)`` at every logged instant, after the trace row."""


@runtime_checkable
class SimDriver(SimView, Protocol):
    """A running simulation its owner runs and changes (see the module docstring)."""

    def initialize(self) -> None:
        """Build the schedule and initialize every component (once)."""

    def advance(self, until_tick: int) -> None:
        """Execute every instant up to ``until_tick`` (a Ctrl-C raised after)."""

    def run(self) -> RunResult:
        """Run to the end."""

    def result(self) -> RunResult:
        """Samples and events so far."""

    def apply_live(self, change: Change) -> Fraction:
        """Queue a change made by hand; returns the instant it lands at."""

    def write(self, buffer: str, value: float) -> None:
        """Set a buffer from another thread, between instants."""

    def record_event(self, kind: str, detail: str) -> None:
        """Record an event at the current simulated time."""

    def hold_quality(self, waiting: bool) -> None:
        """Take no quality sample while ``waiting`` (the signal holds no measurement yet)."""

    def close(self) -> None:
        """Release what the run holds outside the process (a ROS 2 graph), if anything."""

    def release(self) -> None:
        """Drop the finished run's objects at once (``release.py``); unusable afterwards."""


@runtime_checkable
class ServiceHost(Protocol):
    """What a run's shared service (``Context.shared``: the physics world) is given."""

    @property
    def world(self) -> WorldSpec:
        """The world the run steps."""

    @property
    def now(self) -> Fraction:
        """Exact simulated time now."""

    def add_hook(self, rate_hz: Fraction, fn: Hook, name: str) -> None:
        """Call ``fn()`` at ``rate_hz`` after the components due at the same instant."""

    def batch_hook(self, fn: Hook, many: Callable[[int, Callable[[int], None]], int]) -> None:
        """Let the hook ``fn`` take a run of its instants in one call."""

    def record_event(self, kind: str, detail: str) -> None:
        """Record an event at the current simulated time."""


@runtime_checkable
class BatchDriver(SimDriver, Protocol):
    """A batch of runs stepped together (``multirun.MultiRun``)."""

    @property
    def runs(self) -> Sequence[Any]:
        """Each run's own view: its events, live changes and result."""

    @property
    def members(self) -> Sequence[Mapping[str, Template]]:
        """Each run's components by path."""

    @property
    def column_physics(self) -> Any:
        """The batch's column physics (``physics/columns.py``), or None."""

    def outcomes(self) -> list[Any]:
        """Each run's samples, events and changes so far."""

    def run_of(self, fault: BaseException) -> int | None:
        """The run a fault belongs to, if any one run's."""


#: every name a face declares: what the structure test lets code outside ``engine/`` read
FACES = (SimView, SimDriver, ServiceHost, BatchDriver)


def declared(face: type) -> frozenset[str]:
    """The attribute names ``face`` (a protocol here) declares, its bases' included."""
    out: set[str] = set()
    for klass in face.__mro__:
        if klass in (Protocol, object) or not getattr(klass, "_is_protocol", False):
            continue
        out |= {n for n in vars(klass) if not n.startswith("_")}
    return frozenset(out)
