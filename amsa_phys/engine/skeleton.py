"""A run's structure kept across runs of one world: a reset compiles no time grid twice.

A Gymnasium ``reset`` (``gym/follow.py``) builds a new
:class:`~amsa_phys.engine.runner.Simulation` of the same world for every episode; only the
seed changes. Of ``Simulation._compile``, the tick grid (a gcd over every period and
instant, in Fractions), the timer phases and the tasks (each Leaf's ports resolved to
positions in the buffer store, its period and phase in ticks) depend only on the world, its
timeline, the run's duration and log rate, and the hooks' rates; they were a fifth of such
a build. A :class:`Skeleton` keeps them, and a later run of the same structure takes them
from it: its tasks are copies of the kept ones with the run's own component, a fresh
record of the Leaf's own outputs and, for a delayed Leaf, a delay line seeded by the run's
seed (its random jitter and its last due tick are the run's own).

What counts as "the same": the very world object (frozen: a change is a new object,
``model/worldspec.py``), an equal timeline (a scenario's own object, or a world run alone
for a duration: one made per run), equal duration, log rate and hook rates, a single run and
no adaptation rules (their column extends the store). A world with random timer phases
draws them per seed and is compiled afresh every time. ``tests/engine/test_skeleton.py``
holds a run built from a kept skeleton to a fresh compilation's, task by task and trace
for trace.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any

from ..model.timeline import Timeline
from ..model.timing import RANDOM
from ..model.world import WorldSpec
from .build import make_task
from .clock import TickGrid
from .tasks import Task
from .timing import DelayLine, run_phases

if TYPE_CHECKING:
    from .runner import Simulation

#: How many skeletons are kept (the oldest dropped first): one env or loop needs one
MAX_KEPT = 8


@dataclass(frozen=True)
class Skeleton:
    """One structure's grid, timer phases and tasks (see the module docstring)."""

    world: WorldSpec
    timeline: Timeline
    duration: Fraction
    log_rate: Fraction
    hook_rates: tuple[Fraction, ...]
    grid: TickGrid
    phases: dict[str, Fraction]
    #: the tasks as compiled for the first run, with its component and own outputs removed
    protos: tuple[dict[str, Any], ...]
    #: each task's Leaf if it has a delay line (made afresh per run), else None
    delayed: tuple[Any, ...]

    def tasks(self, members: dict[str, Any], seed: int) -> list[Task]:
        """The run's tasks: the kept ones with its components, each a fresh record of its
        own outputs, and a delay line drawn from ``seed`` where the Leaf has one."""
        out = []
        tick = self.grid.tick
        new = Task.__new__
        for proto, leaf in zip(self.protos, self.delayed, strict=True):
            task = new(Task)
            state = task.__dict__
            state.update(proto)
            state["comp"] = members[proto["path"]]
            state["own"] = {}
            if leaf is not None:
                state["delay"] = DelayLine(leaf, tick, seed)
            out.append(task)
        return out


_kept: dict[int, Skeleton] = {}


def fixed_phases(world: WorldSpec) -> bool:
    """Whether every Leaf's timer phase is the same whatever the seed (none is drawn)."""
    free = world.free_running
    for leaf in world.leaves.values():
        phase = leaf.timing.phase
        if phase == RANDOM or (phase is None and free):
            return False
    return True


def hook_rates(sim: Simulation) -> tuple[Fraction, ...]:
    """The rates of ``sim``'s hooks, in the order they were added."""
    return tuple(rate for rate, _, _ in sim._hooks)


def kept(sim: Simulation) -> Skeleton | None:
    """The skeleton kept for ``sim``'s structure, if any (and if ``sim`` may use one)."""
    if len(sim.worlds) != 1 or sim._adapt is not None:
        return None
    found = _kept.get(id(sim.world))
    if (
        found is None
        or found.world is not sim.world
        or (found.timeline is not sim.timeline and found.timeline != sim.timeline)
        or found.duration != sim.duration
        or found.log_rate != sim.log_rate
        or found.hook_rates != hook_rates(sim)
    ):
        return None
    return found


def keep(sim: Simulation, grid: TickGrid, phases: dict[str, Fraction], tasks: list[Task]) -> None:
    """Record ``sim``'s freshly compiled grid, phases and tasks, if a later run of the same
    structure may reuse them (a single run, no adaptation rules, no drawn phases)."""
    world = sim.world
    if len(sim.worlds) != 1 or sim._adapt is not None or not fixed_phases(world):
        return
    protos = []
    for task in tasks:
        state = dict(task.__dict__)
        state["comp"] = None
        state["own"] = None
        state["delay"] = None
        protos.append(state)
    delayed = tuple(world.leaves[t.path] if t.delay is not None else None for t in tasks)
    if len(_kept) >= MAX_KEPT:
        _kept.pop(next(iter(_kept), 0), None)  # another thread may have dropped it
    _kept[id(world)] = Skeleton(
        world,
        sim.timeline,
        sim.duration,
        sim.log_rate,
        hook_rates(sim),
        grid,
        dict(phases),
        tuple(protos),
        delayed,
    )


def compile_tasks(sim: Simulation) -> tuple[TickGrid, dict[str, Fraction], list[Task]]:
    """``sim``'s tick grid, its (first) run's timer phases and its tasks: from the skeleton
    kept for its structure, else compiled afresh (and kept where a later run may reuse
    them)."""
    found = kept(sim)
    if found is not None:
        return found.grid, dict(found.phases), found.tasks(sim.members[0], sim.seed)
    order = sim.world.order
    # a batch's runs share their world and timeline objects point by point: each is read
    # once (a Fraction division a Leaf and run, and a timeline's points a run, were a third
    # of this function in a 250-run batch)
    worlds = {id(w): w for w in sim.worlds}.values()
    timelines = {id(t): t for t in sim.timelines}.values()
    periods = sorted({1 / f for f in {w.leaves[p].freq for w in worlds for p in order}})
    periods += [1 / r for r, _, _ in sim._hooks] + [1 / sim.log_rate]
    instants = [p.at for t in timelines for p in t.points()] + [sim.duration]
    #: each Leaf's timer phase in each run (0 unless the world gives or draws one)
    phases = [run_phases(w, seed) for w, seed in zip(sim.worlds, sim.seeds, strict=True)]
    instants += [ph for run in phases for ph in run.values() if ph]
    grid = TickGrid.for_run(periods, instants)
    tasks = [
        make_task(w, path, members[path], grid, ph[path], seed, sim.store, run)
        for path in order
        for run, (w, members, ph, seed) in enumerate(
            zip(sim.worlds, sim.members, phases, sim.seeds, strict=True)
        )
    ]
    keep(sim, grid, phases[0], tasks)
    return grid, phases[0], tasks


def forget() -> None:
    """Drop every kept skeleton (tests compare a fresh compilation with a kept one)."""
    _kept.clear()
