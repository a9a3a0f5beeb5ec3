"""The cycle's layout, kept across runs of one structure: a reset pays no scheduling twice.

A Gymnasium ``reset`` (``gym/follow.py``) or a falsification loop builds a new
:class:`~amsa_phys.engine.runner.Simulation` of the same world for every episode; only the
seed and parameter values change. Laying out the cycle (``schedule.instants``) and merging
like components into groups (``build.plan_groups``) took ~40 % of such a build, and both
depend only on what :func:`signature` collects: each task's path, run, period, timer phase,
inputs and whether it is delayed, each task's group key, the log's and the hooks' periods.
A layout records the result as positions (task ``k`` of the run's task list, hook ``k`` of its
hook list, a group as the tuple of its members' positions); :func:`rebuild` lays the new
run's own objects out by them, in the same order, so the table the hot loop walks is the one
a fresh compilation gives (``tests/engine/test_layout.py`` compares them entry by entry).

Only what the signature says is reused; a world whose seed draws other timer phases, or
whose parameters change a group key, has another signature and is laid out afresh.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass
from typing import Any

from ..errors import RunFault
from . import batch, schedule
from .build import plan_groups
from .clock import TickGrid
from .tasks import Steppers, Task

#: How many layouts are kept (the oldest dropped first): one env or loop needs one
MAX_LAYOUTS = 8

#: A member of a group, as ``apply_change`` names it: (run, path)
Member = tuple[int, str]
#: An instant's item: a task's position, or a group as its members' positions
Item = int | tuple[int, ...]


@dataclass(frozen=True)
class Layout:
    """One structure's cycle: its length and its table (``schedule.runs``: the runs of
    physics-only instants already folded), per entry ``(offset, items, log, hooks, last,
    spacing)`` with tasks, groups and hooks by position."""

    cycle: int
    entries: tuple[tuple[int, tuple[Item, ...], bool, tuple[int, ...], int, int], ...]


_kept: dict[Hashable, Layout] = {}


def signature(
    tasks: Sequence[Task],
    keys: Sequence[Any],
    log_at: int | None,
    hooks: Sequence[tuple[int, Callable[[], None]]],
    grouping: batch.Grouping,
) -> Hashable:
    """Everything the layout depends on (``keys``: each task's group key, in task order)."""
    fns = [fn for _, fn in hooks]
    return (
        tuple(
            (t.path, t.run, t.period, t.phase, t.delay is not None, tuple(t.inputs)) for t in tasks
        ),
        tuple(keys),
        log_at,
        tuple(p for p, _ in hooks),
        tuple(fns.index(fn) for fn in fns),  # which hooks are one function
        grouping.key,
        grouping.min_group,
        grouping.enabled,
    )


def kept(sig: Hashable) -> Layout | None:
    """The layout kept for ``sig``, if any."""
    return _kept.get(sig)


def keep(
    sig: Hashable,
    cycle: int,
    table: Sequence[schedule.Entry],
    tasks: Sequence[Task],
    hooks: Sequence[tuple[int, Callable[[], None]]],
) -> None:
    """Record a freshly planned cycle's table (its entries' tasks as ``(step, item)``
    pairs)."""
    where = {id(t): k for k, t in enumerate(tasks)}
    fns = [fn for _, fn in hooks]
    rows = []
    for off, pairs, log, entry_hooks, last, spacing in table:
        items: list[Item] = []
        for _, item in pairs:
            if isinstance(item, batch.Group):
                items.append(tuple(where[id(m)] for m in item.tasks))
            else:
                items.append(where[id(item)])
        at = tuple(fns.index(h) for h in entry_hooks)
        rows.append((off, tuple(items), log, at, last, spacing))
    if len(_kept) >= MAX_LAYOUTS:
        _kept.pop(next(iter(_kept), None), None)  # another thread may have dropped it
    _kept[sig] = Layout(cycle, tuple(rows))


def rebuild(
    layout: Layout,
    tasks: Sequence[Task],
    hooks: Sequence[tuple[int, Callable[[], None]]],
    steppers: Steppers,
) -> tuple[list[schedule.Entry], dict[Member, list[batch.Group]]]:
    """The cycle's table with this run's tasks, groups and hooks, as ``schedule.runs``
    makes it from a fresh layout, and the groups each member steps in, as
    ``build.plan_groups`` returns them. Why the table and not the instants: most instants
    of a cycle are the physics step alone (44 of scenario1's 50), folded into a few
    entries; made again at every reset, they were most of this rebuild."""
    for_group = steppers.for_group
    for_task = steppers.for_task
    fns = [fn for _, fn in hooks]
    made: dict[tuple[int, ...], batch.Group] = {}
    steps: dict[tuple[int, ...], Callable[..., None]] = {}  # each group's, made once
    groups_of: dict[Member, list[batch.Group]] = {}
    out: list[schedule.Entry] = []
    for off, items, log, hook_at, last, spacing in layout.entries:
        pairs: list[tuple[Any, Any]] = []
        for item in items:
            if type(item) is int:
                task = tasks[item]
                pairs.append((for_task(task), task))
                continue
            group = made.get(item)  # type: ignore[arg-type]
            if group is None:
                group = made[item] = batch.Group([tasks[k] for k in item])  # type: ignore[union-attr]
                steps[item] = for_group(group)  # type: ignore[index]
            pairs.append((steps[item], group))  # type: ignore[index]
            for member in group.tasks:
                groups = groups_of.setdefault(batch.ident(member), [])
                if group not in groups:
                    groups.append(group)
        out.append((off, tuple(pairs), log, tuple(fns[k] for k in hook_at), last, spacing))
    return out, groups_of


def forget() -> None:
    """Drop every kept layout (tests compare a fresh compilation with a kept one)."""
    _kept.clear()


def lay_out(
    tasks: list[Task],
    worlds: Sequence[Any],
    grouping: Any,
    steppers: Steppers,
    grid: TickGrid,
    log_at: int | None,
    hooks: list[tuple[int, Any]],
) -> tuple[int, list[schedule.Entry], dict[Any, Any]]:
    """A run's cycle length, its table (``schedule.runs``) with like components grouped,
    and the groups: by the layout kept from an earlier run of the same structure (a single
    run's, where resets repeat it), else laid out afresh and kept."""
    freq = lambda t: worlds[t.run].leaves[t.path].freq  # noqa: E731
    sig = None
    if len(worlds) == 1:
        key = grouping.key
        sig = signature(tasks, [key(t, freq(t)) for t in tasks], log_at, hooks, grouping)
        found = kept(sig)
        if found is not None:
            table, groups_of = rebuild(found, tasks, hooks, steppers)
            return found.cycle, table, groups_of
    try:
        length, cycle = schedule.instants(tasks, log_at, hooks)
    except schedule.TooManyEvents as exc:
        raise RunFault(
            "scheduler",
            0,
            f"the rates repeat only every "
            f"{float(grid.time(exc.cycle)):g} s ({exc.count} events); use "
            "commensurate frequencies",
        ) from None
    groups_of = plan_groups(cycle, tasks, freq, grouping, steppers)
    table = schedule.runs(cycle)
    if sig is not None:
        keep(sig, length, table, tasks, hooks)
    return length, table, groups_of
