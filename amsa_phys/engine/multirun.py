"""Many runs of one scenario as rows of one simulation (``amsa-phys sweep --executor batch``).

A sweep's runs differ only in parameter values set at t = 0 and in their seed; their worlds
have the same components, rates and timeline instants. :class:`MultiRun` steps them as one
:class:`~amsa_phys.engine.runner.Simulation` with an integer *run axis*: the buffer store
holds one row per run in every column (``store.py``), there is one task per (Leaf, run),
and the engine's grouping (``engine/batch.py``) steps the runs' copies of a Leaf in one
``step_many`` call whose inputs and outputs are the Leaf's columns, read and written in
place. Nothing is renamed: every run's components keep their paths. What makes each run the
run it would be alone:

* its random streams: a component's stream is keyed by (run's seed, path), exactly
  :func:`rng.component_rng` of the run alone;
* its parameters and timeline: the run's own world and t = 0 values build its components,
  its later changes are applied to its own components at their instants;
* its shared services: ``ctx.shared`` is per run, so each run has its own physics world
  (its own pymunk Space, see :class:`RunView`): runs never touch, and rovers of one run
  collide with each other and that run's obstacles exactly as alone;
* its events and quality samples, kept per run, from which its metrics are computed;
* its faults: a fault is marked with its run (``tasks.in_run``), which ``run_batch`` then
  makes alone.

Groups are formed at any size (``Grouping(min_group=1)``), so a run's arithmetic is the same
whatever batch it lands in: a batched sweep is byte-identical to itself across batch sizes
and ``-j``. Against the run made alone it can differ only where array arithmetic rounds
unlike the scalar code (numpy's transcendental functions, see ``engine/batch.py``; on the
pure path also the numpy force model): ~1e-13 in the rovers' distance over a run, held to
1e-9 by the tests; with the compiled step the tests' rows are equal to the last bit.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from ..model.scenario import Change, Scenario
from . import batch
from .rng import component_rng
from .runner import Context, Event, RunResult, Simulation
from .signals import RequirementWatch
from .tasks import Task


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

    def batch_hook(self, fn: Callable[[], None], many: Callable[[int, Any], int]) -> None:
        """Let the batch's hook ``fn`` take a run of its instants in one call
        (``Simulation.batch_hook``: the column physics' steps)."""
        self._sim.batch_hook(fn, many)

    def record_event(self, kind: str, detail: str) -> None:
        """An event of this run at the current simulated time."""
        self.events.append(Event(float(self._sim.now), kind, detail))


class RunContext(Context):
    """A component's ``initialize`` context inside a batch: its run's streams and services."""

    def __init__(self, sim: MultiRun, path: str, run: int) -> None:
        self._sim = sim
        self.path = path
        self.run = run
        self._run = sim.runs[run]
        self.world = self._run.world

    def __getattr__(self, name: str) -> Any:
        """``rng``, made at its first use: the stream the run alone gives (keyed by the run's
        seed and the path, so the same whenever it is made). Most of a batch's components
        draw nothing (robots, monitors, controllers); a Generator each cost a batch of
        scenario1 ~0.05 ms a run at set-up."""
        if name == "rng":
            self.rng = rng = component_rng(self._run.seed, self.path)
            return rng
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

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


class JudgedOnce(RequirementWatch):
    """A batch's requirement watch that judges each set of samples once.

    A batch's end asks twice: ``Simulation.run`` ends with ``result()`` (run 0's verdicts)
    and the sweep then asks :meth:`MultiRun.outcomes` for every run's. Judging is the STL
    monitor over every run's samples (~0.14 ms a run of scenario1), so the second ask
    reuses the first's verdicts while no sample was added; each caller gets its own dicts.
    """

    _memo: tuple[int, list[dict[str, Any]]] | None = None

    def judged(self) -> list[dict[str, Any]]:
        """Every run's requirements judged (see :meth:`RequirementWatch.judged`)."""
        n = self.sampler.count()
        if self._memo is None or self._memo[0] != n:
            self._memo = (n, super().judged())
        return [{name: dict(entry) for name, entry in run.items()} for run in self._memo[1]]


class MultiRun(Simulation):
    """Runs of one scenario's world, stepped together (see the module's docstring).

    ``scenarios`` must share duration, log rate and world structure (``runs/batched.py``
    checks that before it puts them in one batch). ``ungrouped`` names templates whose
    ``step_many`` needs all members in one shared service (the robots' physics world, when
    each run steps its own), or says so of an initialized component: they step one by one.
    ``columns`` takes over the runs' physics steps (``physics/columns.py``).
    ``keep_log=False`` (a vector env's batch, as the single env's run): no quality samples,
    so no log instants unless a trace or listener asks for them (``Simulation``).
    """

    def __init__(
        self,
        scenarios: Sequence[Scenario],
        ungrouped: Collection[type] | Callable[[Any], bool] = (),
        columns: Any = None,
        keep_log: bool = True,
    ) -> None:
        self.scenarios = list(scenarios)
        #: the batch's column physics (``physics/columns.py``), which takes over every
        #: run's physics step; None: each run's world steps its own Space
        self.column_physics = columns
        self._ungrouped = ungrouped if callable(ungrouped) else tuple(ungrouped)
        base = self.scenarios[0]
        self.runs: list[RunView] = [RunView(self, sc) for sc in self.scenarios]
        super().__init__(
            base.world,
            seed=base.seed,
            duration=base.duration,
            log_rate=base.log_rate,
            grouping=batch.Grouping(self._batch_key, min_group=1),
            context=MultiRun._run_context,
            runs=self.scenarios,
            keep_log=keep_log,
        )
        #: each run's quality signal: its position in the store (None: the run has none)
        store = self.store
        self._q_at = [
            store.at(sc.quality.signal, i) if sc.quality else None
            for i, sc in enumerate(self.scenarios)
        ]
        self._q_index = [i for i, at in enumerate(self._q_at) if at is not None]
        where = np.array([at for at in self._q_at if at is not None], dtype=np.intp)
        first = int(where[0]) if len(where) else 0
        if len(where) and (where == first + np.arange(len(where))).all():
            self._q_where: slice | np.ndarray = slice(first, first + len(where))
        else:
            self._q_where = where
        self._q_t = array("d")
        self._q_rows: list[np.ndarray] = []
        if self._q_index and keep_log:
            self.add_log_listener(self._sample)
        #: the runs' STL requirements, judged as one batch (a column per run)
        self.watch = JudgedOnce.of(base, self)

    def _sample(self, t_s: float, values: Any) -> None:
        """One quality sample of every run: a copy of the signal's column (one C call)."""
        self._q_rows.append(self.store.col[self._q_where].copy())
        self._q_t.append(t_s)

    def _run_context(self, path: str, run: int) -> Context:
        return RunContext(self, path, run)

    def _batch_key(self, task: Task, freq: Fraction) -> tuple[Any, ...] | None:
        cls = type(task.comp)
        if not hasattr(cls, "step_many") or cls.has_arrays():
            return None
        alone = self._ungrouped
        if alone(task.comp) if callable(alone) else issubclass(cls, alone):
            return None
        delay = task.delay
        if delay is not None and delay.draw is not None:
            return None
        latency = None if delay is None else delay.fixed
        inputs = tuple(sorted(p for p, _ in task.inputs))
        return (task.path, cls, freq, task.phase, latency, inputs)

    def release(self) -> None:
        """:meth:`Simulation.release` for every run: each run's shared services (its physics
        world) let go of their cycles too, so an ended batch is freed by reference counting
        (a vector env's reset drops ~230 objects an env; left to the cyclic collector, one
        full collection walked them all: ~90 ms at 1,000 envs). Twice is fine."""
        if self.released:
            return
        for run in self.runs:
            for value in run.shared.values():
                release = getattr(value, "release_run", None)
                if release is not None:
                    release()
            run.shared.clear()
        columns = self.column_physics
        if columns is not None and hasattr(columns, "release"):
            columns.release()
        super().release()

    @staticmethod
    def run_of(fault: BaseException) -> int | None:
        """The run a fault belongs to (``tasks.in_run``), if any one run's."""
        run = getattr(fault, "run", None)
        return run if isinstance(run, int) else None

    def outcomes(self) -> list[BatchShare]:
        """Each run's samples, events and changes so far."""
        t = np.array(self._q_t[: len(self._q_rows)], dtype=np.float64)
        shape = (len(self._q_rows), len(self._q_index))
        table = np.array(self._q_rows, dtype=np.float64).reshape(shape)
        column = {k: j for j, k in enumerate(self._q_index)}
        t_end = float(self.now)
        judged = self.watch.judged() if self.watch else None
        out = []
        for i, run in enumerate(self.runs):
            j = column.get(i)
            samples = table[:, j].copy() if j is not None else np.zeros(0)
            times = t if j is not None else np.zeros(0)
            reqs = judged[i] if judged is not None else None
            out.append(BatchShare(RunResult(t_end, times, samples, list(run.events), reqs)))
        return out
