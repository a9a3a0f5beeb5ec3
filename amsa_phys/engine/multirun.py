"""Many runs of one scenario as columns of one simulation (``amsa-phys sweep --executor batch``).

A sweep's runs differ only in parameter values set at t = 0 and in their seed; their worlds
have the same components, rates and timeline instants. :class:`MultiRun` builds one world
that holds every run as a renamed copy of the scenario's root (``R0.Leader``,
``R1.Leader``, ...), so the engine's grouping (``engine/batch.py``) steps like components
of all runs in one ``step_many`` call, keyed by the component's path *within* its run. What
makes each copy the run it would be alone:

* its random streams: a component's stream is keyed by (run's seed, path within the run),
  exactly :func:`rng.component_rng` of the run alone;
* its parameters and timeline: the run's t = 0 values build its components, its later
  changes are applied to its own components at their instants;
* its shared services: ``ctx.shared`` is per run, so each run has its own physics world
  (its own pymunk Space, see :class:`RunView`): runs never touch, and rovers of one run
  collide with each other and that run's obstacles exactly as alone;
* its events and quality samples, kept per run, from which its metrics are computed.

Groups are formed at any size (``Grouping(min_group=1)``), so a run's arithmetic is the same
whatever batch it lands in: a batched sweep is byte-identical to itself across batch sizes
and ``-j``. Against the run made alone it can differ only where array arithmetic rounds
unlike the scalar code (numpy's transcendental functions, see ``engine/batch.py``; on the
pure path also the numpy force model): ~1e-13 in the rovers' distance over a run, held to
1e-9 by the tests; with the compiled step the tests' rows are equal to the last bit.
"""

from __future__ import annotations

import operator
from array import array
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, field, replace
from fractions import Fraction
from typing import Any

import numpy as np

from ..model.scenario import Change, Phase, Scenario, Step
from ..model.world import BufferSpec, CompositeSpec, WorldSpec
from . import batch
from .rng import component_rng
from .runner import Context, Event, RunResult, Simulation, _Task


def prefix_of(index: int) -> str:
    """The name of run ``index``'s copy of the root in the batch's world."""
    return f"R{index}"


class RunView:
    """What a run's shared services (its physics world) see: the batch's clock and hooks,
    the run's own world settings, seed and event list."""

    def __init__(self, sim: MultiRun, scenario: Scenario) -> None:
        self._sim = sim
        self.world = scenario.world
        self.seed = scenario.seed
        self.shared: dict[str, Any] = {}
        self.events: list[Event] = []

    @property
    def now(self) -> Fraction:
        """The batch's (every run's) simulated time."""
        return self._sim.now

    @property
    def column_physics(self) -> Any:
        """The batch's column physics (``physics/columns.py``), which steps every run's
        physics world in one pass, or None: a run's physics world asks for it by this name."""
        return self._sim.column_physics

    def add_hook(self, rate_hz: Fraction, fn: Callable[[], None], name: str) -> None:
        """A subsystem step of this run, stepped by the batch."""
        self._sim.add_hook(rate_hz, fn, name)

    def record_event(self, kind: str, detail: str) -> None:
        """An event of this run at the current simulated time."""
        self.events.append(Event(float(self._sim.now), kind, detail))


class RunContext(Context):
    """A component's ``initialize`` context inside a batch: its run's streams and services."""

    def __init__(self, sim: MultiRun, path: str, run: RunView, local: str) -> None:
        self._sim = sim
        self.path = path
        self.rng = component_rng(run.seed, local)  # the stream the run alone gives ``local``
        self.world = sim.world
        self._run = run

    def shared(self, name: str, factory: Callable[[Any], Any]) -> Any:
        """The run's own shared service ``name`` (each run has its own physics world)."""
        if name not in self._run.shared:
            self._run.shared[name] = factory(self._run)
        return self._run.shared[name]

    def record_event(self, kind: str, detail: str) -> None:
        """Record an event of this run."""
        self._run.record_event(kind, detail)


@dataclass
class BatchShare:
    """One run's share of a finished batch: what ``compute_metrics`` needs (not to be
    confused with ``runs.single.RunOutcome``, what a run wrote to disk)."""

    result: RunResult
    live_changes: list[tuple[Fraction, Change]] = field(default_factory=list)


def merged_world(worlds: Sequence[WorldSpec]) -> WorldSpec:
    """One world holding ``worlds`` (of the same structure) as renamed copies of the root.

    The execution order is component-major (``R0.Leader, R1.Leader, ..., R0.Follower, ...``):
    within each run the world's own order, so every read sees what it sees alone.
    """
    base = worlds[0]
    leaves = {}
    buffers = {}
    arrays = {}
    for i, world in enumerate(worlds):
        pre = prefix_of(i) + "."
        for path, leaf in world.leaves.items():
            leaves[pre + path] = replace(
                leaf,
                path=pre + path,
                inputs={port: pre + buf for port, buf in leaf.inputs.items()},
            )
        for name, buf in world.buffers.items():
            buffers[pre + name] = BufferSpec(pre + name, pre + buf.producer, buf.port, buf.initial)
        for name, elements in world.arrays.items():
            arrays[pre + name] = [pre + e for e in elements]
    order = [prefix_of(i) + "." + path for path in base.order for i in range(len(worlds))]
    return replace(
        base,
        root=CompositeSpec(path=""),
        leaves=leaves,
        buffers=buffers,
        order=order,
        schedule=list(order),
        data_names={},
        arrays=arrays,
    )


def merged_phases(scenarios: Sequence[Scenario]) -> list[Phase]:
    """Every run's timeline as one: t = 0 values, then each change at its instant.

    Later changes become steps of one phase (phases only name spans of a run; each run's
    metrics use its own). At one instant, a run's changes keep their order.
    """
    first: list[Change] = []
    later: dict[Fraction, list[Change]] = {}
    for i, sc in enumerate(scenarios):
        pre = prefix_of(i) + "."
        timeline = sc.timeline
        first += [_renamed(c, pre) for c in timeline.initial]
        for point in timeline.points():
            later.setdefault(point.at, []).extend(_renamed(c, pre) for c in point.changes)
    steps = [Step(at, changes) for at, changes in sorted(later.items())]
    return [Phase(Fraction(0), first, within=steps)]


def _renamed(change: Change, pre: str) -> Change:
    return Change(pre + change.leaf, change.param, change.value, change.written)


class MultiRun(Simulation):
    """Runs of one scenario's world, stepped together (see the module's docstring).

    ``scenarios`` must share duration, log rate and world structure (``runs/batched.py``
    checks that before it puts them in one batch). ``ungrouped`` names templates whose
    ``step_many`` needs all members in one shared service (the robots' physics world, when
    each run steps its own): they step one by one here. ``columns`` takes over the runs'
    physics steps (``physics/columns.py``).
    """

    def __init__(
        self,
        scenarios: Sequence[Scenario],
        ungrouped: Collection[type] = (),
        columns: Any = None,
    ) -> None:
        self.scenarios = list(scenarios)
        #: the batch's column physics (``physics/columns.py``), which takes over every
        #: run's physics step; None: each run's world steps its own Space
        self.column_physics = columns
        self._ungrouped = tuple(ungrouped)
        base = self.scenarios[0]
        self.runs: list[RunView] = []
        world = merged_world([sc.world for sc in self.scenarios])
        super().__init__(
            world,
            seed=base.seed,
            duration=base.duration,
            phases=merged_phases(self.scenarios),
            log_rate=base.log_rate,
            grouping=batch.Grouping(self._batch_key, min_group=1),
            context=MultiRun._run_context,
        )
        self.runs = [RunView(self, sc) for sc in self.scenarios]
        quality = [
            prefix_of(i) + "." + sc.quality.signal if sc.quality else None
            for i, sc in enumerate(self.scenarios)
        ]
        self._q_index = [i for i, q in enumerate(quality) if q is not None]
        names = [q for q in quality if q is not None]
        self._q_get: Callable[[dict[str, float]], Any] | None = (
            None
            if not names
            else operator.itemgetter(*names)
            if len(names) > 1
            else (lambda v: (v[names[0]],))
        )
        self._q_t = array("d")
        self._q_rows: list[tuple[float, ...]] = []
        if self._q_get is not None:
            self.add_log_listener(self._sample)

    def _sample(self, t_s: float, values: dict[str, float]) -> None:
        assert self._q_get is not None
        self._q_rows.append(self._q_get(values))
        self._q_t.append(t_s)

    def _run_context(self, path: str) -> Context:
        head, _, local = path.partition(".")
        return RunContext(self, path, self.runs[int(head[1:])], local)

    def _batch_key(self, task: _Task, freq: Fraction) -> tuple[Any, ...] | None:
        cls = type(task.comp)
        if not hasattr(cls, "step_many") or cls.has_arrays() or issubclass(cls, self._ungrouped):
            return None
        delay = task.delay
        if delay is not None and delay.draw is not None:
            return None
        latency = None if delay is None else delay.fixed
        local = task.path.partition(".")[2]
        inputs = tuple(sorted(p for p, _ in task.inputs))
        return (local, cls, freq, task.phase, latency, inputs)

    def run_of(self, component: str) -> int | None:
        """The run a component path (or a fault's ``who``) belongs to, if any."""
        head, dot, _ = component.partition(".")
        if dot and head[:1] == "R" and head[1:].isdigit():
            k = int(head[1:])
            return k if k < len(self.runs) else None
        return None

    def outcomes(self) -> list[BatchShare]:
        """Each run's samples, events and changes so far."""
        t = np.array(self._q_t[: len(self._q_rows)], dtype=np.float64)
        shape = (len(self._q_rows), len(self._q_index))
        table = np.array(self._q_rows, dtype=np.float64).reshape(shape)
        column = {k: j for j, k in enumerate(self._q_index)}
        t_end = float(self.now)
        out = []
        for i, run in enumerate(self.runs):
            j = column.get(i)
            samples = table[:, j].copy() if j is not None else np.zeros(0)
            times = t if j is not None else np.zeros(0)
            out.append(BatchShare(RunResult(t_end, times, samples, list(run.events))))
        return out
