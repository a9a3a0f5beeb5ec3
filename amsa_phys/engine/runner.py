"""The simulation loop: components at their own rates on one exact clock.

At every instant the engine does, in this order:

1. apply the changes due at that instant (``_apply_instant``): delayed outputs that arrive
   then, the timeline's changes (a new phase starts) and any other instant source's
   (adaptation rules), then live changes made by hand;
2. run the components due then, in execution order (``model.dataflow``); each reads its
   inputs at its start and publishes its outputs at its end (run-to-completion);
3. record a trace row if the log is due;
4. run the hooks due then (the physics advances from t to t + dt).

So a component due at t sees the world as it is at t. The whole schedule repeats with the
hyperperiod of all rates and is precomputed once as a table of (offset, actions): the loop
does no scheduling arithmetic per instant, and a run of instants where only the physics step
is due (four in five at 100 Hz physics with a 20 Hz trace) is one table entry stepped in a
tight loop.

This module is the facade and the hot loop; the engine's other concepts live in rooms of
their own (``docs/architecture.md``): the buffer store (``store.py``), the schedule compiler
(``schedule.py``), the tasks and their output checks (``tasks.py``), the delivery heap of
delayed publications (``delivery.py``), the instant-level changes (``instants.py``) and the
log (``log.py``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from fractions import Fraction
from heapq import heappush
from typing import Any

from ..errors import RunFault
from ..model.adaptrules import RULE_COLUMN, Rule
from ..model.scenario import Change, Phase, Scenario
from ..model.template import Template
from ..model.timeline import Timeline
from ..model.world import WorldSpec
from . import batch, interrupt, layout, schedule, skeleton, walk
from .adapt import AdaptRules
from .build import build_components
from .clock import NOWS_KEPT, exact, kept_times
from .context import Context, Event, Hook, RunResult
from .delivery import Deliveries
from .facereads import FaceReads
from .fromscenario import FromScenario
from .instants import InstantSource, TimelineSource
from .livechanges import LiveChanges
from .log import RunLog
from .plugs import Plugs
from .release import Release
from .signals import RequirementWatch
from .store import BufferStore, ReadAPI
from .tasks import COMPONENT_ERRORS, Steppers, Task, in_run
from .timing import DelayLine

#: Wraps a component as it is built: ``wrap(path, component)`` returns what the engine runs
#: in its place (the ROS simulator's remote Leaves), see :class:`Simulation`.
Wrap = Callable[[str, Template], Template]

__all__ = ["COMPONENT_ERRORS", "Context", "Event", "RunResult", "Simulation", "Task", "Wrap"]


class Simulation(ReadAPI, FaceReads, LiveChanges, FromScenario, Release):
    """One run of a scenario (or of a bare world, for tests).

    Read from outside with :meth:`read`, :meth:`read_many`, :meth:`column` and
    :meth:`write` (``store.ReadAPI``).

    ``wrap`` is the construction hook: each component, once built, is passed through
    ``wrap(path, component)`` and the engine runs what it returns, so a caller that stands
    a component in for another (a remote Leaf, a recorder) does it here rather than by
    replacing entries of :attr:`components` or methods of a component afterwards.
    ``grouping=False`` steps like copies leaf by leaf (``batch.py``), for a caller whose
    components must each be called (a ROS node per Leaf) or a test's reference run; a
    ``batch.Grouping`` says how to group instead. ``context(sim, path)`` makes what each
    component's ``initialize`` receives (a batch of runs gives each run its own).
    ``plugs``: what a runtime changes at an instant (``plugs.py``); outsiders see ``face.py``.
    ``keep_log=False``: no log instants unless a trace or listener is there (``gym/episode.py``).
    """

    def __init__(
        self,
        world: WorldSpec,
        *,
        seed: int = 0,
        duration: Fraction = Fraction(10),
        phases: Sequence[Phase] = (),
        timeline: Timeline | None = None,
        log_rate: Fraction = Fraction(20),
        quality_signal: str | None = None,
        trace: Callable[[float, list[float]], None] | None = None,
        columns: Sequence[str] | None = None,
        adapt: Sequence[Rule] = (),
        wrap: Wrap | None = None,
        grouping: bool | batch.Grouping = True,
        context: Callable[[Simulation, str, int], Context] = Context,
        runs: Sequence[Scenario] = (),
        plugs: Plugs | None = None,
        keep_log: bool = True,
    ) -> None:
        self.world = world
        self.plugs = plugs if plugs is not None else Plugs()
        self.seed = seed
        self.duration = Fraction(timeline.duration if timeline is not None else duration)
        #: ``runs``: a batch of runs of ``world``'s structure (``multirun.py``) stepped
        #: together, each with its own parameters, timeline and seed; the store then holds
        #: one row per run in every column. Alone: the batch of one (``world``, ``phases``)
        self.worlds = [sc.world for sc in runs] or [world]
        self.seeds = [sc.seed for sc in runs] or [seed]
        #: each run's timeline (``model/timeline.py``): the scenario's own, planned bounds
        #: included (a world run alone: one made of ``phases`` and ``duration``)
        if timeline is None:
            timeline = Timeline.of(phases, self.duration)
        self.timelines = [sc.timeline for sc in runs] or [timeline]
        self.timeline = self.timelines[0]
        self.log_rate = Fraction(log_rate)
        self.shared: dict[str, Any] = {}
        self.events: list[Event] = []
        #: every buffer's value, one float64 array (``store.py``); read with :meth:`read`
        self.store = BufferStore.of_worlds(self.worlds, [RULE_COLUMN] if adapt else [])
        #: the same values by name (a view: tests and listeners speak names)
        self.values = self.store.values
        #: the buffers of a trace row, in order (all of them unless ``trace_columns:`` chose)
        self.columns = list(world.buffers) if columns is None else list(columns)
        self.log = RunLog(
            self.columns, trace, quality_signal, self.store.at, self.values, self.store.col
        )
        self._keep_log = keep_log
        self._hooks: list[tuple[Fraction, Hook, str]] = []
        #: hooks that take a run of their instants in one call (:meth:`batch_hook`)
        self._many: dict[Hook, Callable[[int, Callable[[int], None]], int]] = {}
        self._run_first = self._run_spacing = 0  # the run of instants ``many`` is taking
        #: each run's components by path (one dict for a single run)
        self.members: list[dict[str, Template]] = [{} for _ in self.timelines]
        #: the (first) run's components by path
        self.components: dict[str, Template] = self.members[0]
        self._wrap = wrap
        #: how like copies step as arrays (``batch.py``); False: leaf by leaf, a reference
        self.grouping = grouping if isinstance(grouping, batch.Grouping) else batch.Grouping()
        if grouping is False:
            self.grouping = batch.Grouping(enabled=False)
        self._new_context = context
        self._tick = 0  # the instant being executed, in ticks (``now`` derives from it)
        self._now_override: Fraction | None = None
        self._now_cache: tuple[int, Fraction] = (0, Fraction(0))
        self.phase_index = 0
        self.change_log: list[tuple[Fraction, Change]] = []
        self.live_changes: list[tuple[Fraction, Change]] = []
        self._pending_live: list[Change] = []
        self._initialized = False
        self._cursor = 0  # next tick to execute
        #: publications of delayed Leaves in flight (``delivery.py``)
        self.deliveries = Deliveries()
        #: sources of changes at exact instants, the timeline first (``instants.py``)
        self._sources: list[InstantSource] = []
        self._next_instant_tick: float = math.inf  # deliveries' or sources', the earliest
        self._next_source_tick: float = math.inf  # the instant sources' alone
        self._steppers = Steppers(self.store.data, self._send, self._who, self.store.col)
        #: ``adapt:`` rules (``engine/adapt.py``), asked at every instant with components
        self._adapt = AdaptRules(adapt, self._param_value) if adapt else None
        #: the STL requirements judged after the run (:meth:`watch_requirements`)
        self.watch: RequirementWatch | None = None
        self._build()

    # -- construction -------------------------------------------------------------------
    def _build(self) -> None:
        for members, timeline, world in zip(self.members, self.timelines, self.worlds, strict=True):
            members.update(build_components(world, timeline, self._wrap))

    def initialize(self) -> None:
        """The paper's initialize(): cascades to every Leaf (in execution order; in a batch
        every run's copy of a Leaf, then the next Leaf's)."""
        if self._initialized:
            return
        self._initialized = True
        for path in self.world.order:
            for run, members in enumerate(self.members):
                try:
                    members[path].initialize(self._new_context(self, path, run))
                except RunFault as exc:
                    in_run(exc, run)
                    raise
                except COMPONENT_ERRORS as exc:  # a component's own bug or configuration
                    fault = RunFault(self._who(path), 0, f"initialize failed: {exc!r}")
                    raise in_run(fault, run) from exc
        self._compile()

    def add_hook(self, rate_hz: Fraction, fn: Hook, name: str) -> None:
        """See :meth:`Context.add_hook`."""
        if self._initialized and hasattr(self, "_table"):
            raise RuntimeError("hooks must be added during initialize")
        self._hooks.append((Fraction(rate_hz), fn, name))

    def batch_hook(self, fn: Hook, many: Callable[[int, Callable[[int], None]], int]) -> None:
        """Let the hook ``fn`` (added with :meth:`add_hook`) take a run of its instants in
        one call where nothing else is due between them: ``many(count, seek)`` takes up to
        ``count`` of them, as ``count`` calls of ``fn`` at those instants would, and returns
        how many it took (the loop calls ``fn`` for the rest); before it raises, it calls
        ``seek(k)`` to move the clock to the ``k``-th instant (0: the first), where its
        fault happened. The physics step batches its steps so (``physics/space.py``)."""
        self._many[fn] = many

    def add_instant_source(self, source: InstantSource) -> None:
        """Apply ``source``'s changes at their exact instants (``instants.py``), after the
        timeline's at the same instant and before live changes and the components: the
        place adaptation rules plug in. Call after :meth:`initialize` (the tick grid is
        known then) and before the instants concerned run."""
        self.initialize()
        self._sources.append(source)
        self._next_source_tick = min(self._next_source_tick, source.next_tick())
        self._next_instant_tick = min(self._next_instant_tick, self._next_source_tick)

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
        # exact(n, d): ``grid.tick * tick`` costs three times as much, Fraction(n, d) twice
        now = exact(self._tick * self._tick_num, self._tick_den)
        self._now_cache = (self._tick, now)
        return now

    def _compile(self) -> None:
        # the grid, the phases and the tasks: an earlier run's of this structure (a reset's)
        # where ``skeleton.py`` kept them, else compiled afresh
        self.grid, self.timer_phases, self._tasks = skeleton.compile_tasks(self)
        g = self.grid
        self._tick_num, self._tick_den = g.tick.numerator, g.tick.denominator
        self._log_period = g.ticks(1 / self.log_rate)
        self.keeps_log = bool(self._keep_log or self.log.listeners or self.log.has_trace)
        log_at = self._log_period if self.keeps_log else None
        hooks = [(g.ticks(1 / r), fn) for r, fn, _ in self._hooks]
        self._table = self._lay_out(log_at, hooks)
        self._plan = schedule.merges(self._table, self._many)
        self._end = g.ticks(self.duration)
        self._sources[:0] = [TimelineSource(t, g, r) for r, t in enumerate(self.timelines)]
        self._next_source_tick = min(s.next_tick() for s in self._sources)
        self._next_instant_tick = min(self._next_source_tick, self.deliveries.next_due())
        #: the compiled schedule walk (``walk.py``), or None: the Python loop of ``_advance``
        self._walk = walk.prepare(self)

    def _lay_out(self, log_at: int | None, hooks: list[tuple[int, Hook]]) -> list[schedule.Entry]:
        """The cycle's table with like components grouped (sets ``_cycle`` and
        ``_groups_of``): :func:`layout.lay_out`, afresh or as kept from an earlier run."""
        self._cycle, table, self._groups_of = layout.lay_out(
            self._tasks, self.worlds, self.grouping, self._steppers, self.grid, log_at, hooks
        )
        return table

    # -- running --------------------------------------------------------------------------
    def run(self) -> RunResult:
        """Run to the end of the scenario."""
        self.initialize()
        self.advance(self._end)
        return self.result()

    @property
    def finished(self) -> bool:
        """Whether the run reached its duration."""
        return self._initialized and self._cursor > self._end

    def advance(self, until_tick: int) -> None:
        """Execute every instant with tick <= ``until_tick`` (and <= the end).

        A Ctrl-C noted meanwhile (:mod:`.interrupt`) is raised here, once every instant up
        to ``until_tick`` has run whole. The store's lock is held meanwhile: a write from
        another thread (:meth:`write`) lands between calls, never inside an instant.
        """
        with self.store.lock, interrupt.stepping():
            self._advance(until_tick)
        if interrupt.requested():
            raise KeyboardInterrupt
        if self._cursor > self._end:  # ``finished`` without its property call (a gym step's)
            self.plugs.run_ended()

    def _advance(self, until_tick: int) -> None:
        """:meth:`advance` without the interrupt check.

        The hot loop of every run: per instant it does two integer compares, then calls what
        the precomputed table lists. Instant-level changes (deliveries, the timeline, rules)
        are found by comparing with the next one's tick only; hooks (the physics step) do not
        run at the final instant, which ends the run. Where the extension is built this very
        loop runs in C (``walk.py``); the Python below is its reference and the pure path.
        """
        self.initialize()
        until = min(until_tick, self._end)
        # the same loop in one C call where built (``walk.py``); below, the reference
        walker = self._walk
        if walker is not None and not walk.current(walker, self):
            walker = self._walk = walk.prepare(self)
        if walker is not None:
            walker(self, until)
            return
        cycle = self._cycle
        table = self._plan
        end = self._end
        cursor = self._cursor
        record, values = self.log.record, self.store.data
        num, den = self._tick_num, self._tick_den
        adapt = self._adapt  # fixed at construction
        many_of, seek = self._many, self._seek
        nows = kept_times(num, den)
        deliver, data, col = self.deliveries.deliver, self.store.data, self.store.col
        try:
            while cursor <= until:
                base = (cursor // cycle) * cycle
                for off, tasks, log, hooks, last_off, spacing, merge in table:
                    first = base + off
                    last = base + last_off
                    if last < cursor:
                        continue
                    if (
                        last_off != off
                        and first >= cursor
                        and last <= until
                        and last < end
                        and last < self._next_instant_tick
                        and not self._pending_live
                    ):
                        # a whole run of hook-only instants (physics steps between log rows):
                        # nothing else can happen in between, so no checks per instant
                        if len(hooks) == 1:  # the usual case: the physics step alone
                            hook = hooks[0]
                            start = first
                            many = many_of.get(hook) if many_of else None
                            if many is not None:
                                self._tick = self._run_first = first
                                self._run_spacing = spacing
                                done = many((last - first) // spacing + 1, seek)
                                if done:
                                    start = first + done * spacing
                                    self._tick = start - spacing
                            for tick in range(start, last + 1, spacing):
                                self._tick = tick
                                hook()
                        else:
                            for tick in range(first, last + 1, spacing):
                                self._tick = tick
                                for hook in hooks:
                                    hook()
                        cursor = last + 1
                        continue
                    # one instant (the usual entry) or a run the checks above refused
                    for tick in (first,) if last_off == off else range(first, last + 1, spacing):
                        if tick < cursor:
                            continue
                        if tick > until:
                            cursor = tick
                            return
                        if tick >= self._next_instant_tick:
                            if self._next_source_tick > tick:  # deliveries alone are due
                                nxt = deliver(tick, data, col)  # ``_apply_instant`` inlined
                                source = self._next_source_tick
                                self._next_instant_tick = nxt if nxt < source else source
                            else:
                                self._apply_instant(tick)
                        self._tick = tick
                        if self._pending_live:
                            self._apply_live()
                        if tasks:
                            if adapt is not None:
                                self._apply_adapt()
                            # the ``now`` property's Fraction, built here without its checks,
                            # once per instant of the grid (an env's episodes repeat them)
                            now = nows.get(tick)
                            if now is None:
                                now = exact(tick * num, den)
                                if len(nows) < NOWS_KEPT:
                                    nows[tick] = now
                            self._now_cache = (tick, now)
                            try:
                                for run, task in tasks:
                                    run(task, now)
                            except RunFault as exc:
                                if isinstance(task, Task):  # a group's fault names its run
                                    in_run(exc, task.run)
                                raise
                        if log:
                            # float(tick * n) without building a Fraction: int / int is
                            # correctly rounded, the same float ``float(Fraction)`` gives
                            record((tick * num) / den, values)
                        if tick < end:
                            if merge is not None and tick == first:
                                # this instant's hook and the run of it alone that follows
                                # in one batch, when nothing else can happen in that run
                                run_last = base + merge[0]
                                if (
                                    run_last <= until
                                    and run_last < end
                                    and run_last < self._next_instant_tick
                                    and not self._pending_live
                                ):
                                    step = merge[1]
                                    self._run_first, self._run_spacing = tick, step
                                    done = merge[2]((run_last - tick) // step + 1, seek)
                                    hook = hooks[0]
                                    for rest in range(tick + done * step, run_last + 1, step):
                                        self._tick = rest
                                        hook()
                                    self._tick = run_last
                                    cursor = run_last + 1
                                    continue
                            for hook in hooks:
                                hook()
                        cursor = tick + 1
                cursor = max(cursor, base + cycle)
        finally:
            # after a fault inside a run of physics-only instants ``cursor`` is still the
            # run's start; the instant that failed is ``_tick``, as on the general path
            self._cursor = max(cursor, self._tick)

    def _seek(self, k: int) -> None:
        """The clock at the ``k``-th instant of the run a batched hook is taking."""
        self._tick = self._run_first + k * self._run_spacing

    def _apply_instant(self, tick: int) -> None:
        """THE point where instant-level changes are applied, before the components due at
        ``tick``: deliveries of delayed outputs, then each instant source's changes (the
        timeline's first; ``instants.py``). Afterwards ``_next_instant_tick`` is the next
        tick at which any of them is due, so the hot loop makes one comparison for all."""
        nxt = self.deliveries.deliver(tick, self.store.data, self.store.col)
        if self._next_source_tick <= tick:
            for source in self._sources:
                if source.next_tick() <= tick:
                    for at, phase, changes in source.due(tick):
                        if phase is not None:
                            self.phase_index = phase
                        self._now_override = when = self.grid.time(at)
                        run = getattr(source, "run", 0)
                        try:
                            for change in changes:
                                if run:
                                    self._change(change, run)
                                else:  # the single run's (a runtime may judge it first)
                                    self.apply_change(self.plugs.timeline_change(change, when))
                        finally:
                            self._now_override = None
            self._next_source_tick = min(s.next_tick() for s in self._sources)
        self._next_instant_tick = min(nxt, self._next_source_tick)

    def _send(self, line: DelayLine, writes: list[tuple[int, float]]) -> None:
        """Put a delayed Leaf's publication in flight: visible from ``line.due(now)``."""
        if line.draw is None:  # ``due`` and ``push`` inlined: each step of the single env
            due = self._tick + line.fixed
            if due < line.last:
                due = line.last
            line.last = due
            heap = self.deliveries  # ``push`` inlined
            heap._sent += 1
            heappush(heap._heap, (due, heap._sent, writes))
        else:
            due = line.due(self._tick)
            self.deliveries.push(due, writes)
        if due < self._next_instant_tick:
            self._next_instant_tick = due

    def in_flight(self, buffer: str) -> int:
        """How many publications of ``buffer`` are sent but not yet visible (the ROS
        simulator tells a node which message its reader sees by this)."""
        return self.deliveries.in_flight(self.store.at(buffer))

    def add_log_listener(self, fn: Callable[[float, dict[str, float]], None]) -> None:
        """Call ``fn(t_s, values)`` at every logged instant, after the trace row.

        The window and the video sample trails, GPS fixes and live metrics here: per
        simulated instant, the very samples ``metrics.json`` is computed from, whatever the
        frame rate or speed-up (at x256 a frame spans seconds of simulated time).
        """
        if not getattr(self, "keeps_log", True):
            raise RuntimeError("this run keeps no log (keep_log=False): add listeners before it")
        self.log.listeners.append(fn)

    def result(self) -> RunResult:
        """Samples and events so far (and the requirements judged, if any)."""
        samples_t, samples_s = self.log.samples()
        return RunResult(
            t_end=float(self.now),
            samples_t=samples_t,
            samples_s=samples_s,
            events=list(self.events),
            requirements=self.watch.judged()[0] if self.watch else None,
            adapt_switches=self._adapt.switches if self._adapt is not None else 0,
        )

    def _who(self, path: str) -> str:
        leaf = self.world.leaves.get(path)
        return f"{path} ({leaf.template.name()})" if leaf else path
