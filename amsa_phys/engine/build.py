"""From a world to what the hot loop runs: tasks bound to the store, groups planned.

``Simulation._compile`` (``runner.py``) asks this module for each Leaf's :class:`Task` (its
ports resolved to positions in the buffer store, its timer phase and delay line on the tick
grid) and, once the schedule compiler (``schedule.py``) has laid out the cycle's instants,
for the groups of like components (``batch.py``) merged into each instant. A batch of runs
(``multirun.py``) has one task per (Leaf, run), in component-major order: every run's copy
of a Leaf, then the next Leaf's, so within each run the world's order holds.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from fractions import Fraction

from ..model.template import Template
from ..model.timeline import Timeline
from ..model.world import WorldSpec
from . import batch, schedule
from .clock import TickGrid
from .store import BufferStore
from .tasks import Steppers, Task
from .timing import DelayLine

#: A group's member, as ``apply_change`` names it: (run, path)
Member = tuple[int, str]


def build_components(
    world: WorldSpec,
    timeline: Timeline,
    wrap: Callable[[str, Template], Template] | None,
) -> dict[str, Template]:
    """Every Leaf's component, built with its phase-0 parameters (in force at initialize),
    in execution order; each passed through ``wrap`` if given (``Simulation(wrap=)``)."""
    leaves = world.leaves
    params = {path: dict(leaf.params) for path, leaf in leaves.items()}
    for change in timeline.initial:
        params[change.leaf][change.param] = change.value
    out = {}
    for path in world.order:
        comp = leaves[path].template(path, params[path])
        out[path] = comp if wrap is None else wrap(path, comp)
    return out


def make_task(
    world: WorldSpec,
    path: str,
    comp: Template,
    grid: TickGrid,
    phase: Fraction,
    seed: int,
    store: BufferStore,
    run: int = 0,
) -> Task:
    """``path``'s Leaf in run ``run`` as the schedule runs it, bound to ``store``."""
    leaf = world.leaves[path]
    arrays = world.arrays
    task = Task(
        path,
        comp,
        period_ticks(grid, leaf.freq),
        list(leaf.inputs.items()),
        {p.name: f"{path}.{p.name}" for p in leaf.template.outputs},
        run=run,
    )
    for port in leaf.template.inputs:
        if port.array and port.name in leaf.inputs:
            task.arrays_in[port.name] = arrays[leaf.inputs[port.name]]
    for port in leaf.template.outputs:
        if port.array:
            task.arrays_out[port.name] = arrays[f"{path}.{port.name}"]
    task.phase = grid.ticks(phase) if phase else 0
    if leaf.timing.delayed:
        task.delay = DelayLine(leaf, grid.tick, seed)
    task.bind(lambda name: store.at(name, run))
    return task


def period_ticks(grid: TickGrid, freq: Fraction) -> int:
    """``grid.ticks(1 / freq)`` in integers: a batch makes a task per (Leaf, run), and two
    Fraction divisions a task were a tenth of a batch's planning. Off the grid: the same
    ValueError as ``grid.ticks``."""
    num = freq.denominator * grid.tick.denominator
    den = freq.numerator * grid.tick.numerator
    if den <= 0 or num % den:
        return grid.ticks(1 / freq)
    return num // den


def plan_groups(
    cycle: Sequence[schedule.Instant],
    tasks: Sequence[Task],
    freq: Callable[[Task], Fraction],
    grouping: batch.Grouping,
    steppers: Steppers,
) -> dict[Member, list[batch.Group]]:
    """Merge like components into groups where that changes no read (``batch.py``): each
    instant's tasks become ``(step, task or group)`` pairs. Returns the groups each member
    steps in (a parameter change must refresh their arrays)."""
    keys = {batch.ident(t): grouping.key(t, freq(t)) for t in tasks}
    planned = batch.plan([i.tasks for i in cycle], keys, grouping.min_group, grouping.enabled)
    groups_of: dict[Member, list[batch.Group]] = {}
    steps: dict[int, Callable[..., None]] = {}  # a group's step, made once (``for_group``)
    for inst, seq in zip(cycle, planned, strict=True):
        inst.tasks = []
        for item in seq:
            if isinstance(item, batch.Group):
                step = steps.get(id(item))
                if step is None:
                    step = steps[id(item)] = steppers.for_group(item)
                inst.tasks.append((step, item))
            else:
                inst.tasks.append((steppers.for_task(item), item))
        for item in seq:
            if isinstance(item, batch.Group):
                for member in item.tasks:
                    groups = groups_of.setdefault(batch.ident(member), [])
                    if item not in groups:
                        groups.append(item)
    return groups_of
