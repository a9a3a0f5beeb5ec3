"""The schedule compiler: from periods and timer phases to the table the hot loop walks.

Pure: it takes the tasks' periods and phases in ticks, the log's period and the hooks'
periods, and returns what happens at each offset of the repeating cycle (the hyperperiod of
all of them) in the order the engine runs it — components (in the world's execution order),
then the trace row, then the hooks (the physics step). :func:`runs` then folds runs of
hook-only instants (the physics steps between two log rows) into one table entry, so the
loop steps them without any per-instant check. No clock, no components, no numbers from
the run: unit-testable on plain integers (``tests/engine/test_schedule.py``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from .clock import MAX_EVENTS_PER_CYCLE, hyperperiod

Hook = Callable[[], None]

#: A table entry: ``(offset, tasks, log, hooks, last, spacing)``; ``tasks`` are the pairs
#: ``(step, task)`` the loop calls as ``step(task, now)``.
Entry = tuple[int, tuple[Any, ...], bool, tuple[Hook, ...], int, int]


class TooManyEvents(ValueError):
    """The rates repeat only after more than :data:`MAX_EVENTS_PER_CYCLE` events."""

    def __init__(self, cycle: int, count: int) -> None:
        super().__init__(f"{count} events in a cycle of {cycle} ticks")
        self.cycle = cycle
        self.count = count


@dataclass
class Instant:
    """What happens at one offset of the repeating cycle, in the order the engine runs it."""

    offset: int
    tasks: list[Any] = field(default_factory=list)
    log: bool = False
    hooks: list[Hook] = field(default_factory=list)


def cycle_of(
    task_periods: Sequence[int], log_period: int | None, hook_periods: Sequence[int]
) -> int:
    """The hyperperiod of every period, in ticks (TooManyEvents if it holds too many)."""
    periods = [*task_periods, *([log_period] if log_period else []), *hook_periods]
    cycle = hyperperiod(periods)
    count = sum(cycle // p for p in periods)
    if count > MAX_EVENTS_PER_CYCLE:
        raise TooManyEvents(cycle, count)
    return cycle


def instants(
    tasks: Sequence[Any],
    log_period: int | None,
    hooks: Sequence[tuple[int, Hook]],
) -> tuple[int, list[Instant]]:
    """The cycle's length and its instants in offset order.

    ``tasks`` have ``period`` and ``phase`` (ticks), in execution order; ``hooks`` are
    ``(period, fn)`` in the order they were added. Only offsets where something is due appear.
    ``log_period`` None: a run that keeps no log (no instant is due for the log alone, so
    the physics steps between two components' instants are one run).
    """
    cycle = cycle_of([t.period for t in tasks], log_period, [p for p, _ in hooks])
    table: dict[int, Instant] = {}
    for task in tasks:
        for off in range(task.phase, cycle, task.period):
            table.setdefault(off, Instant(off)).tasks.append(task)
    for off in range(0, cycle, log_period) if log_period else ():
        table.setdefault(off, Instant(off)).log = True
    for period, fn in hooks:
        for off in range(0, cycle, period):
            table.setdefault(off, Instant(off)).hooks.append(fn)
    return cycle, [i for _, i in sorted(table.items())]


def runs(cycle_instants: list[Instant]) -> list[Entry]:
    """The cycle's instants as table entries ``(offset, tasks, log, hooks, last, spacing)``.

    Consecutive instants with only the same hooks (the physics steps between two log rows)
    become one entry covering ``offset, offset + spacing, ..., last``; any other instant is
    its own entry with ``last == offset``.
    """
    out: list[Entry] = []
    for i in cycle_instants:
        hooks = tuple(i.hooks)
        if out and not i.tasks and not i.log:
            off, tasks, log, prev_hooks, last, spacing = out[-1]
            hook_only = not tasks and not log and prev_hooks == hooks
            if hook_only and (last == off or i.offset - last == spacing):
                out[-1] = (off, tasks, log, hooks, i.offset, i.offset - last)
                continue
        out.append((i.offset, tuple(i.tasks), i.log, hooks, i.offset, 1))
    return out


def next_tick(table: Sequence[Entry], cycle: int, cursor: int) -> int:
    """The first tick at or after ``cursor`` at which the table has something to run."""
    base = (cursor // cycle) * cycle
    for off, _, _, _, last_off, spacing in table:
        for tick in range(base + off, base + last_off + 1, spacing):
            if tick >= cursor:
                return tick
    return base + cycle + table[0][0]


def merges(table: Sequence[Entry], many: Mapping[Hook, Any]) -> list[tuple[Any, ...]]:
    """The table's entries, each with what its hook may take in the same batch.

    For an instant whose single hook batches (``many``: ``Simulation.batch_hook``) and is
    followed at once by a run of that hook alone (evenly spaced), ``(last, spacing, batch)``
    of that run: the loop hands the instant's hook and the run to ``batch`` in one call
    when nothing else is due in it. None otherwise.
    """
    plan: list[tuple[Any, ...]] = []
    for i, (off, tasks, log, hooks, last_off, spacing) in enumerate(table):
        merge = None
        after = table[i + 1] if i + 1 < len(table) else None
        if last_off == off and len(hooks) == 1 and hooks[0] in many and after:
            n_off, n_tasks, n_log, n_hooks, n_last, n_spacing = after
            alone = not n_tasks and not n_log and n_hooks == hooks
            if alone and (n_last == n_off or n_spacing == n_off - off):  # evenly spaced
                merge = (n_last, n_off - off, many[hooks[0]])
        plan.append((off, tasks, log, hooks, last_off, spacing, merge))
    return plan
