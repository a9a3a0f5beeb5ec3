"""The schedule walk in one C call: ``Simulation._advance``'s loop, compiled.

Why: a Gymnasium env-step of the follow world is three instants with components and three
batches of physics steps, and walking the precomputed table in Python around them (the
entries passed over, the compares with the next instant's tick, the clock, the calls) cost
as much as the agent's own step. ``_kernels.walk`` runs the very same loop, statement for
statement, over the table as numbers (offsets, runs, merges) and the table's objects (the
tasks' steps, the hooks, the batched hooks): it calls the same components and hooks in the
same order at the same ticks, reads every attribute the Python loop reads at each use (the
next instant's tick, pending live changes) and writes every one it writes (the clock, a
batch's run, the cursor, whatever happens), and goes back to the simulation's Python methods
for the rare rest (an instant source's changes, live changes, adaptation rules). So the run is
the same bit for bit and fault for fault (``tests/engine/test_walk.py``).

The Python loop stays the reference and runs wherever the walk does not: the pure path
(``AMSA_PHYS_PURE=1``), a build without the extension, ticks beyond 62 bits (the C loop
counts in 64-bit integers), and a table replaced after it was prepared.
"""

from __future__ import annotations

from array import array
from typing import TYPE_CHECKING, Any

from ..errors import RunFault
from . import publish
from .clock import NOWS_KEPT, exact, kept_times
from .tasks import Task
from .verdicts import in_run

if TYPE_CHECKING:
    from .runner import Simulation

#: the walk's ticks stay below this (sums of two of them fit in a signed 64-bit integer)
LIMIT = 1 << 61


class Walk:
    """One simulation's table as the C walk takes it, and the loop's other locals."""

    __slots__ = ("fn", "helpers", "key", "nums", "objs")

    def __init__(self, sim: Simulation, fn: Any) -> None:
        self.fn = fn
        self.key = _key(sim)
        nums = array("q")
        objs = []
        for off, tasks, log, hooks, last_off, spacing, merge in sim._plan:
            m_last, m_step, batch = (-1, 0, None) if merge is None else merge
            nums.extend((off, last_off, spacing, 1 if log else 0, m_last, m_step))
            steps = tuple((run, task) for run, task in tasks)
            objs.append((steps, tuple(hooks), batch))
        self.nums = nums
        self.objs = tuple(objs)
        num, den = sim._tick_num, sim._tick_den
        self.helpers = (
            kept_times(num, den),
            exact,
            NOWS_KEPT,
            Task,
            in_run,
            RunFault,
            sim.log.record,
            sim.store.data,
            sim.deliveries.deliver,
            sim.store.col,
            sim._seek,
            sim._many,
            num,
            den,
        )

    def __call__(self, sim: Simulation, until: int) -> None:
        """Execute every instant with tick <= ``until`` (already at most the end)."""
        self.fn(sim, self.nums, self.objs, until, sim._cursor, sim._cycle, sim._end, self.helpers)


def _key(sim: Simulation) -> tuple[Any, ...]:
    """What a prepared walk holds of ``sim``: if any of it was replaced, prepare again."""
    return (sim._plan, sim.log, sim.deliveries, sim.store.data, sim._many)


def prepare(sim: Simulation) -> Walk | None:
    """The compiled walk of ``sim``'s table, or None: the Python loop (see the module
    docstring)."""
    module = publish._extension("_kernels")
    fn = getattr(module, "walk", None) if module is not None else None
    if fn is None or sim._end >= LIMIT or sim._cycle >= LIMIT:
        return None
    return Walk(sim, fn)


def current(walk: Walk | None, sim: Simulation) -> bool:
    """Whether ``walk`` is still ``sim``'s (nothing it holds was replaced)."""
    if walk is None:
        return False
    key = walk.key
    return (
        key[0] is sim._plan
        and key[1] is sim.log
        and key[2] is sim.deliveries
        and key[3] is sim.store.data
        and key[4] is sim._many
    )
