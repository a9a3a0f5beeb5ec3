"""The simulation loop: components at their own rates on one exact clock.

At every instant the engine does, in this order:

1. apply timeline changes due at that instant (a new phase starts);
2. run the components due then, in execution order (``model.dataflow``); each reads its
   inputs at its start and publishes its outputs at its end (run-to-completion);
3. record a trace row if the log is due;
4. run the hooks due then (the physics advances from t to t + dt).

So a component due at t sees the world as it is at t. The whole schedule repeats with the
hyperperiod of all rates and is precomputed once as a table of (offset, actions): the loop
does no scheduling arithmetic per instant, and a run of instants where only the physics step
is due (four in five at 100 Hz physics with a 20 Hz trace) is one table entry stepped in a
tight loop.
"""

from __future__ import annotations

import heapq
import math
import operator
from array import array
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from itertools import compress
from typing import Any

import numpy as np

from ..errors import RunFault
from ..model.params import short_repr
from ..model.scenario import Change, Phase, Scenario, traced_columns
from ..model.template import Template
from ..model.timeline import Timeline
from ..model.world import WorldSpec
from . import batch, interrupt
from .clock import MAX_EVENTS_PER_CYCLE, TickGrid, hyperperiod
from .rng import component_rng
from .timing import DelayLine, run_phases

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

    def __init__(self, sim: Simulation, path: str) -> None:
        self._sim = sim
        self.path = path
        self.rng = component_rng(sim.seed, path)
        self.world = sim.world

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
class _Task:
    path: str
    comp: Template
    period: int
    inputs: list[tuple[str, str]]
    targets: dict[str, str]  # output port -> buffer name ("Component.port")
    #: array ports (a lidar's ranges): port -> element buffer names, in order
    arrays_in: dict[str, list[str]] = field(default_factory=dict)
    arrays_out: dict[str, list[str]] = field(default_factory=dict)
    #: loop timing (``engine/timing.py``): the timer's phase in ticks, and the delay line of
    #: a Leaf with latency or jitter (None: its outputs are visible at once)
    phase: int = 0
    delay: DelayLine | None = None
    #: a delayed Leaf's own last outputs, which it reads back at once (as its node does)
    own: dict[str, float] = field(default_factory=dict)


@dataclass
class _Instant:
    """What happens at one offset of the repeating cycle, in the order the engine runs it."""

    offset: int
    tasks: list[_Task] = field(default_factory=list)
    log: bool = False
    hooks: list[Hook] = field(default_factory=list)


@dataclass
class RunResult:
    """What a finished (or interrupted) run produced, for metrics and reports."""

    t_end: float
    samples_t: np.ndarray
    samples_s: np.ndarray
    events: list[Event] = field(default_factory=list)


Entry = tuple[int, tuple[_Task, ...], bool, tuple[Hook, ...], int, int]


def _runs(instants: list[_Instant]) -> list[Entry]:
    """The cycle's instants as table entries ``(offset, tasks, log, hooks, last, spacing)``.

    Consecutive instants with only the same hooks (the physics steps between two log rows)
    become one entry covering ``offset, offset + spacing, ..., last``; any other instant is
    its own entry with ``last == offset``.
    """
    out: list[Entry] = []
    for i in instants:
        hooks = tuple(i.hooks)
        if out and not i.tasks and not i.log:
            off, tasks, log, prev_hooks, last, spacing = out[-1]
            hook_only = not tasks and not log and prev_hooks == hooks
            if hook_only and (last == off or i.offset - last == spacing):
                out[-1] = (off, tasks, log, hooks, i.offset, i.offset - last)
                continue
        out.append((i.offset, tuple(i.tasks), i.log, hooks, i.offset, 1))
    return out


#: What a component's code may raise that is its fault, not the engine's: any exception,
#: and ``sys.exit()`` (SystemExit), which would otherwise end the whole program with its
#: code and no message. KeyboardInterrupt is the user's and stays one.
COMPONENT_ERRORS = (Exception, SystemExit)


def _is_mask(published: Any, n: int) -> bool:
    """Whether ``published`` is a boolean array with one entry per copy."""
    return (
        isinstance(published, np.ndarray)
        and published.dtype == np.bool_
        and published.shape == (n,)
    )


class Simulation:
    """One run of a scenario (or of a bare world, for tests)."""

    def __init__(
        self,
        world: WorldSpec,
        *,
        seed: int = 0,
        duration: Fraction = Fraction(10),
        phases: Sequence[Phase] = (),
        log_rate: Fraction = Fraction(20),
        quality_signal: str | None = None,
        trace: Callable[[float, list[float]], None] | None = None,
        columns: Sequence[str] | None = None,
    ) -> None:
        self.world = world
        self.seed = seed
        self.duration = Fraction(duration)
        #: the run's timeline (``model/timeline.py``): the only reader of the phases here
        self.timeline = Timeline.of(phases, self.duration)
        self.phases = list(self.timeline.phases)
        self.log_rate = Fraction(log_rate)
        self.shared: dict[str, Any] = {}
        self.events: list[Event] = []
        self.values: dict[str, float] = {
            name: float(b.initial) for name, b in world.buffers.items()
        }
        #: the buffers of a trace row, in order (all of them unless ``trace_columns:`` chose)
        self.columns = list(world.buffers) if columns is None else list(columns)
        self._trace = trace
        self._quality = quality_signal
        # quality samples as packed doubles: a 1-hour run logs 72,000 of each, 1 MiB as
        # arrays instead of ~5 MiB of float objects in lists
        self._samples_t = array("d")
        self._samples_s = array("d")
        self._hooks: list[tuple[Fraction, Hook, str]] = []
        self._log_listeners: list[Callable[[float, dict[str, float]], None]] = []
        self.components: dict[str, Template] = {}
        self._tick = 0  # the instant being executed, in ticks (``now`` derives from it)
        self._now_override: Fraction | None = None
        self._now_cache: tuple[int, Fraction] = (0, Fraction(0))
        self.phase_index = 0
        self.change_log: list[tuple[Fraction, Change]] = []
        self.live_changes: list[tuple[Fraction, Change]] = []
        self._pending_live: list[Change] = []
        self._initialized = False
        self._cursor = 0  # next tick to execute
        #: publications of delayed Leaves in flight: (due tick, sequence, [(buffer, value)])
        self._deliveries: list[tuple[int, int, list[tuple[str, float]]]] = []
        self._sent = 0
        self._build()

    @classmethod
    def from_scenario(cls, scenario: Scenario, **kw: Any) -> Simulation:
        """A Simulation configured by a loaded scenario."""
        q = scenario.quality.signal if scenario.quality else None
        return cls(
            scenario.world,
            seed=scenario.seed,
            duration=scenario.duration,
            phases=scenario.phases,
            log_rate=scenario.log_rate,
            quality_signal=q,
            columns=traced_columns(scenario),
            **kw,
        )

    # -- construction -------------------------------------------------------------------
    def _build(self) -> None:
        params = {path: dict(leaf.params) for path, leaf in self.world.leaves.items()}
        for change in self.timeline.initial:  # phase 0 values are in force at initialize
            params[change.leaf][change.param] = change.value
        for path in self.world.order:
            leaf = self.world.leaves[path]
            self.components[path] = leaf.template(path, params[path])

    def initialize(self) -> None:
        """The paper's initialize(): cascades to every Leaf (in execution order)."""
        if self._initialized:
            return
        self._initialized = True
        for path, comp in self.components.items():
            try:
                comp.initialize(self._context(path))
            except RunFault:
                raise
            except COMPONENT_ERRORS as exc:  # a component's own bug or bad configuration
                raise RunFault(self._who(path), 0, f"initialize failed: {exc!r}") from exc
        self._compile()

    def _context(self, path: str) -> Context:
        """What ``path``'s ``initialize`` receives (a batch of runs gives each its own)."""
        return Context(self, path)

    def _group_key(self, task: _Task, freq: Fraction) -> tuple[Any, ...] | None:
        """Which group ``task`` steps in (``engine/batch.py``); a batch of runs keys by the
        path within the run."""
        return batch.group_key(task, freq)

    #: Smallest group stepped as arrays (``batch.MIN_GROUP``; a batch of runs groups always,
    #: so a run's arithmetic does not depend on how many runs share its batch).
    _min_group: int | None = None

    def add_hook(self, rate_hz: Fraction, fn: Hook, name: str) -> None:
        """See :meth:`Context.add_hook`."""
        if self._initialized and hasattr(self, "_table"):
            raise RuntimeError("hooks must be added during initialize")
        self._hooks.append((Fraction(rate_hz), fn, name))

    @property
    def now(self) -> Fraction:
        """Exact simulated time of the instant being executed (or last executed)."""
        if self._now_override is not None:
            return self._now_override
        tick, now = self._now_cache
        if tick == self._tick:
            return now
        if not hasattr(self, "grid"):
            return Fraction(0)
        # Fraction(n, d) directly: ``grid.tick * tick`` costs three times as much
        now = Fraction(self._tick * self._tick_num, self._tick_den)
        self._now_cache = (self._tick, now)
        return now

    def _compile(self) -> None:
        leaves = self.world.leaves
        periods = [1 / leaves[p].freq for p in self.world.order]
        periods += [1 / r for r, _, _ in self._hooks] + [1 / self.log_rate]
        instants = [p.at for p in self.timeline.points()] + [self.duration]
        #: each Leaf's timer phase (0 unless the world gives or draws one): on the grid
        self.timer_phases = run_phases(self.world, self.seed)
        instants += [ph for ph in self.timer_phases.values() if ph]
        self.grid = TickGrid.for_run(periods, instants)
        g = self.grid
        self._tick_num, self._tick_den = g.tick.numerator, g.tick.denominator
        self._tasks = []
        arrays = self.world.arrays
        for path in self.world.order:
            leaf = leaves[path]
            comp = self.components[path]
            task = _Task(
                path,
                comp,
                g.ticks(1 / leaf.freq),
                list(leaf.inputs.items()),
                {p.name: f"{path}.{p.name}" for p in leaf.template.outputs},
            )
            for port in leaf.template.inputs:
                if port.array and port.name in leaf.inputs:
                    task.arrays_in[port.name] = arrays[leaf.inputs[port.name]]
            for port in leaf.template.outputs:
                if port.array:
                    task.arrays_out[port.name] = arrays[f"{path}.{port.name}"]
            task.phase = g.ticks(self.timer_phases[path])
            if leaf.timing.delayed:
                task.delay = DelayLine(leaf, g.tick, self.seed)
            self._tasks.append(task)
        self._log_period = g.ticks(1 / self.log_rate)
        hook_periods = [g.ticks(1 / r) for r, _, _ in self._hooks]
        all_periods = [t.period for t in self._tasks] + [self._log_period] + hook_periods
        self._cycle = hyperperiod(all_periods)
        count = sum(self._cycle // p for p in all_periods)
        if count > MAX_EVENTS_PER_CYCLE:
            raise RunFault(
                "scheduler",
                0,
                f"the rates repeat only every "
                f"{float(g.time(self._cycle)):g} s ({count} events); use "
                "commensurate frequencies",
            )
        table: dict[int, _Instant] = {}
        for task in self._tasks:
            for off in range(task.phase, self._cycle, task.period):
                table.setdefault(off, _Instant(off)).tasks.append(task)
        for off in range(0, self._cycle, self._log_period):
            table.setdefault(off, _Instant(off)).log = True
        for (_, fn, _), period in zip(self._hooks, hook_periods, strict=True):
            for off in range(0, self._cycle, period):
                table.setdefault(off, _Instant(off)).hooks.append(fn)
        instants = [i for _, i in sorted(table.items())]
        # like components of repeated Composites step as arrays where that changes no read
        keys = {t.path: self._group_key(t, leaves[t.path].freq) for t in self._tasks}
        planned = batch.plan([i.tasks for i in instants], keys, self._min_group)
        self._groups_of: dict[str, list[batch.Group]] = {}
        for inst, seq in zip(instants, planned, strict=True):
            inst.tasks = [
                (self._step_group, item)
                if isinstance(item, batch.Group)
                else (self._runner(item), item)
                for item in seq
            ]
            for item in seq:
                if isinstance(item, batch.Group):
                    for path in item.paths:
                        groups = self._groups_of.setdefault(path, [])
                        if item not in groups:
                            groups.append(item)
        self._table = _runs(instants)
        self._end = g.ticks(self.duration)
        self._points = [(g.ticks(p.at), p.phase, p.changes) for p in self.timeline.points()]
        self._point_index = 0
        self._next_phase_tick = self._points[0][0] if self._points else math.inf
        # one row of the trace in column order, gathered in C
        cols = self.columns
        self._row: Callable[[dict[str, float]], Sequence[float]] = (
            operator.itemgetter(*cols) if len(cols) > 1 else lambda v: [v[c] for c in cols]
        )

    def _runner(self, task: _Task) -> Callable[[_Task, Fraction], None]:
        """How a task steps: the lean scalar path, array ports, or through its delay line."""
        if task.arrays_in or task.arrays_out:
            return self._step_arrays
        return self._step if task.delay is None else self._step_delayed

    # -- running --------------------------------------------------------------------------
    def run(self) -> RunResult:
        """Run to the end of the scenario."""
        self.advance(self._end_tick())
        return self.result()

    def _end_tick(self) -> int:
        self.initialize()
        return self._end

    @property
    def finished(self) -> bool:
        """Whether the run reached its duration."""
        return self._initialized and self._cursor > self._end

    def advance(self, until_tick: int) -> None:
        """Execute every instant with tick <= ``until_tick`` (and <= the end).

        A Ctrl-C noted meanwhile (:mod:`.interrupt`) is raised here, once every instant up
        to ``until_tick`` has run whole.
        """
        self._advance(until_tick)
        if interrupt.requested():
            raise KeyboardInterrupt

    def _advance(self, until_tick: int) -> None:
        """:meth:`advance` without the interrupt check.

        The hot loop of every run: per instant it does two integer compares, then calls what
        the precomputed table lists. Phase changes are found by comparing with the next phase's
        tick only; hooks (the physics step) do not run at the final instant, which ends the run.
        """
        self.initialize()
        until = min(until_tick, self._end)
        cycle = self._cycle
        table = self._table
        end = self._end
        cursor = self._cursor
        try:
            while cursor <= until:
                base = (cursor // cycle) * cycle
                for off, tasks, log, hooks, last_off, spacing in table:
                    first = base + off
                    last = base + last_off
                    if last < cursor:
                        continue
                    if (
                        last_off != off
                        and first >= cursor
                        and last <= until
                        and last < end
                        and last < self._next_phase_tick
                        and not self._pending_live
                    ):
                        # a whole run of hook-only instants (physics steps between log rows):
                        # nothing else can happen in between, so no checks per instant
                        if len(hooks) == 1:  # the usual case: the physics step alone
                            hook = hooks[0]
                            for tick in range(first, last + 1, spacing):
                                self._tick = tick
                                hook()
                        else:
                            for tick in range(first, last + 1, spacing):
                                self._tick = tick
                                for hook in hooks:
                                    hook()
                        cursor = last + 1
                        continue
                    for tick in range(first, last + 1, spacing):
                        if tick < cursor:
                            continue
                        if tick > until:
                            cursor = tick
                            return
                        if tick >= self._next_phase_tick:
                            self._enter_phases(tick)
                        self._tick = tick
                        if self._pending_live:
                            self._apply_live()
                        if tasks:
                            now = self.now
                            for run, task in tasks:
                                run(task, now)
                        if log:
                            self._log()
                        if tick < end:
                            for hook in hooks:
                                hook()
                        cursor = tick + 1
                cursor = max(cursor, base + cycle)
        finally:
            # after a fault inside a run of physics-only instants ``cursor`` is still the
            # run's start; the instant that failed is ``_tick``, as on the general path
            self._cursor = max(cursor, self._tick)

    def _enter_phases(self, tick: int) -> None:
        """Apply what is due at or before ``tick``: deliveries of delayed outputs, then the
        timeline changes (new phases and in-phase). ``_next_phase_tick`` is the next tick at
        which either is due, so the hot loop makes one comparison for both."""
        deliveries = self._deliveries
        if deliveries and deliveries[0][0] <= tick:
            values = self.values
            while deliveries and deliveries[0][0] <= tick:
                values.update(heapq.heappop(deliveries)[2])
        points = self._points
        while self._point_index < len(points) and points[self._point_index][0] <= tick:
            at, phase, changes = points[self._point_index]
            self._point_index += 1
            self.phase_index = phase
            self._now_override = self.grid.time(at)
            try:
                for change in changes:
                    self.apply_change(change)
            finally:
                self._now_override = None
        i = self._point_index
        self._next_phase_tick = points[i][0] if i < len(points) else math.inf
        if deliveries and deliveries[0][0] < self._next_phase_tick:
            self._next_phase_tick = deliveries[0][0]

    def _send(self, line: DelayLine, writes: list[tuple[str, float]]) -> None:
        """Put a delayed Leaf's publication in flight: visible from ``line.due(now)``."""
        due = line.due(self._tick)
        self._sent += 1
        heapq.heappush(self._deliveries, (due, self._sent, writes))
        if due < self._next_phase_tick:
            self._next_phase_tick = due

    def in_flight(self, buffer: str) -> int:
        """How many publications of ``buffer`` are sent but not yet visible (the ROS
        simulator tells a node which message its reader sees by this)."""
        return sum(1 for _, _, writes in self._deliveries for b, _ in writes if b == buffer)

    def _step(self, task: _Task, now: Fraction) -> None:
        """Run one component: read its inputs, call ``do_step``, publish its outputs."""
        values = self.values
        inp = {port: values[buf] for port, buf in task.inputs}
        try:
            out = task.comp.do_step(now, inp)
        except RunFault:
            raise
        except COMPONENT_ERRORS as exc:
            raise RunFault(self._who(task.path), now, f"do_step raised {exc!r}") from exc
        if not out:
            return
        targets = task.targets
        try:
            for key, value in out.items():
                number = float(value)
                if number - number != 0.0:  # inf or nan
                    raise ValueError
                values[targets[key]] = number
        except (KeyError, TypeError, ValueError, OverflowError, AttributeError):
            raise self._bad_output(task, out) from None

    def _step_delayed(self, task: _Task, now: Fraction) -> None:
        """:meth:`_step` for a Leaf with latency or jitter: its outputs go into its delay
        line instead of the buffers (it reads its own outputs back at once)."""
        values = self.values
        own = task.own
        inp = {port: own.get(buf, values[buf]) for port, buf in task.inputs}
        try:
            out = task.comp.do_step(now, inp)
        except RunFault:
            raise
        except COMPONENT_ERRORS as exc:
            raise RunFault(self._who(task.path), now, f"do_step raised {exc!r}") from exc
        if not out:
            return
        targets = task.targets
        writes: list[tuple[str, float]] = []
        try:
            for key, value in out.items():
                number = float(value)
                if number - number != 0.0:  # inf or nan
                    raise ValueError
                writes.append((targets[key], number))
        except (KeyError, TypeError, ValueError, OverflowError, AttributeError):
            raise self._bad_output(task, out) from None
        own.update(writes)
        assert task.delay is not None
        self._send(task.delay, writes)

    def _step_arrays(self, task: _Task, now: Fraction) -> None:
        """:meth:`_step` for a leaf with array ports (a lidar and its readers).

        An array input arrives as a float numpy array of its elements; an array output must
        be a sequence of exactly its length, every element finite, and is published whole
        (or not at all, if the key is missing). Kept apart so the scalar path stays lean.
        """
        values = self.values
        arrays_in = task.arrays_in
        inp: dict[str, Any] = {}
        for port, buf in task.inputs:
            names = arrays_in.get(port)
            inp[port] = values[buf] if names is None else np.array([values[n] for n in names])
        try:
            out = task.comp.do_step(now, inp)
        except RunFault:
            raise
        except Exception as exc:
            raise RunFault(self._who(task.path), now, f"do_step raised {exc!r}") from exc
        if not out:
            return
        scalars = {k: v for k, v in out.items() if k not in task.arrays_out}
        writes: list[tuple[str, float]] = []
        for key, value in out.items():
            names = task.arrays_out.get(key)
            if names is None:
                continue
            try:
                arr = np.asarray(value, dtype=np.float64)
            except (TypeError, ValueError):
                raise RunFault(
                    self._who(task.path), now, f"output {key} is not numbers: {value!r}"
                ) from None
            if arr.shape != (len(names),):
                raise RunFault(
                    self._who(task.path),
                    now,
                    f"output {key} has shape {arr.shape}, expected ({len(names)},)",
                )
            bad = np.flatnonzero(~np.isfinite(arr))
            if bad.size:
                k = int(bad[0])
                raise RunFault(self._who(task.path), now, f"output {key}[{k}] is {arr[k]}")
            writes.extend(zip(names, arr.tolist(), strict=True))
        targets = task.targets
        try:
            for key, value in scalars.items():
                number = float(value)
                if number - number != 0.0:  # inf or nan
                    raise ValueError
                writes.append((targets[key], number))
        except (KeyError, TypeError, ValueError):
            raise self._bad_output(task, scalars) from None
        if task.delay is not None:
            self._send(task.delay, writes)
        else:
            values.update(writes)

    def _step_group(self, group: batch.Group, now: Fraction) -> None:
        """Run a group of like components in one call (``engine/batch.py``)."""
        values = self.values
        # array('d', tuple) then a view: a third cheaper than np.array on a tuple of floats
        inp = {port: np.frombuffer(array("d", get(values))) for port, get in group.inputs}
        try:
            out, published = group.template.step_many(
                group.comps, now, inp, group.params, group.state
            )
        except RunFault:
            raise
        except COMPONENT_ERRORS as exc:
            who = self._who(group.paths[0])
            raise RunFault(who, now, f"step_many raised {exc!r}") from exc
        except (TypeError, ValueError) as exc:  # not a pair (outputs, published)
            who = self._who(group.paths[0])
            raise RunFault(who, now, f"step_many must return (outputs, published): {exc}") from exc
        n = len(group.paths)
        if not (isinstance(out, Mapping) and (published is None or _is_mask(published, n))):
            who = self._who(group.paths[0])
            raise RunFault(
                who,
                now,
                f"step_many must return (outputs, published) with a mapping of outputs and "
                f"None or a boolean mask of {n} rows, got ({short_repr(out)}, "
                f"{short_repr(published)})",
            )
        mask = None if published is None else published.tolist()
        for port, arr in out.items():
            bufs = group.outputs.get(port)
            if bufs is None:
                who = self._who(group.paths[0])
                raise RunFault(who, now, f"published unknown output {short_repr(port)}")
            if not (type(arr) is np.ndarray and arr.shape == (n,) and arr.dtype == np.float64):
                try:
                    arr = np.broadcast_to(np.asarray(arr, dtype=np.float64), (n,))
                except (TypeError, ValueError, OverflowError):
                    raise RunFault(
                        self._who(group.paths[0]),
                        now,
                        f"output {port} of step_many has shape {np.shape(arr)}, expected "
                        f"({n},): one number per copy",
                    ) from None
            k = batch.first_bad(arr, published)
            if k is not None:
                raise RunFault(self._who(group.paths[k]), now, f"output {port} is {arr[k]}")
            pairs = zip(bufs, arr.tolist(), strict=True)
            if group.delay is not None:  # the copies' common latency (no jitter: batch.py)
                self._send(group.delay, list(pairs if mask is None else compress(pairs, mask)))
            else:
                values.update(pairs if mask is None else compress(pairs, mask))

    def _bad_output(self, task: _Task, out: Any) -> RunFault:
        """The fault for the first output ``_step`` refused (a slow path: faults are rare)."""
        who = self._who(task.path)
        if not isinstance(out, Mapping):
            return RunFault(
                who, self.now, f"do_step must return a mapping of outputs, got {short_repr(out)}"
            )
        for key, value in out.items():
            if key not in task.targets:
                return RunFault(who, self.now, f"published unknown output {short_repr(key)}")
            try:
                number = float(value)
            except OverflowError:
                return RunFault(who, self.now, f"output {key} is too large for a float")
            except (TypeError, ValueError):
                return RunFault(who, self.now, f"output {key} is not a number: {short_repr(value)}")
            if not math.isfinite(number):
                return RunFault(who, self.now, f"output {key} is {number}")
        return RunFault(who, self.now, f"published invalid outputs {dict(out)!r}")

    def _log(self) -> None:
        # float(tick * n) without building a Fraction: int / int is correctly rounded, the
        # same float ``float(Fraction)`` gives
        t_s = (self._tick * self._tick_num) / self._tick_den
        values = self.values
        if self._trace is not None:
            self._trace(t_s, self._row(values))
        if self._quality is not None:
            self._samples_t.append(t_s)
            self._samples_s.append(values[self._quality])
        if self._log_listeners:
            for listener in self._log_listeners:
                listener(t_s, values)

    def add_log_listener(self, fn: Callable[[float, dict[str, float]], None]) -> None:
        """Call ``fn(t_s, values)`` at every logged instant, after the trace row.

        The window and the video sample trails, GPS fixes and live metrics here: per
        simulated instant, the very samples ``metrics.json`` is computed from, whatever the
        frame rate or speed-up (at x256 a frame spans seconds of simulated time).
        """
        self._log_listeners.append(fn)

    @property
    def pending_live(self) -> list[Change]:
        """Live changes queued for the next instant, not yet applied."""
        return list(self._pending_live)

    def apply_change(self, change: Change) -> None:
        """Set a parameter now (timeline or live); the component is told after."""
        comp = self.components[change.leaf]
        setattr(comp.p, change.param, change.value)
        for group in getattr(self, "_groups_of", {}).get(change.leaf, ()):
            group.params.invalidate()
        self.change_log.append((self.now, change))
        try:
            comp.on_param_change(change.param, change.value)
        except RunFault:
            raise
        except COMPONENT_ERRORS as exc:
            why = f"on_param_change raised {exc!r}" if isinstance(exc, SystemExit) else exc
            raise RunFault(
                self._who(change.leaf), self.now, f"rejected {change.param}={change.value!r}: {why}"
            ) from None  # a rejection is a message, not a crash (--debug still finds it)

    def next_instant(self) -> Fraction:
        """Time of the next instant at which something runs (where a live change lands)."""
        self.initialize()
        base = (self._cursor // self._cycle) * self._cycle
        for off, _, _, _, last_off, spacing in self._table:
            for tick in range(base + off, base + last_off + 1, spacing):
                if tick >= self._cursor:
                    return self.grid.time(tick)
        return self.grid.time(base + self._cycle + self._table[0][0])

    def apply_live(self, change: Change) -> Fraction:
        """Queue a change made by hand (the window); it lands at :meth:`next_instant`.

        It is applied after the timeline changes due at that instant and before the
        components, exactly where a timeline entry at that time would be, so writing it into
        the resolved scenario's timeline replays the session. Returns the instant.
        """
        at = self.next_instant()
        self._pending_live.append(change)
        return at

    def _apply_live(self) -> None:
        pending, self._pending_live = self._pending_live, []
        for change in pending:
            self.apply_change(change)
            self.live_changes.append((self.now, change))
            self.record_event("live change", f"{change.key}={change.value}")

    def record_event(self, kind: str, detail: str) -> None:
        """See :meth:`Context.record_event`."""
        self.events.append(Event(float(self.now), kind, detail))

    def result(self) -> RunResult:
        """Samples and events so far."""
        # equal lengths even if a second Ctrl-C (raised at once) fell between the two appends
        n = min(len(self._samples_t), len(self._samples_s))
        return RunResult(
            t_end=float(self.now),
            samples_t=np.array(self._samples_t[:n], dtype=np.float64),
            samples_s=np.array(self._samples_s[:n], dtype=np.float64),
            events=list(self.events),
        )

    def _who(self, path: str) -> str:
        leaf = self.world.leaves.get(path)
        return f"{path} ({leaf.template.name()})" if leaf else path
