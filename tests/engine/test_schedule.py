"""The schedule compiler (engine/schedule.py) on plain integers, and the delivery heap."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from amsa_phys.engine import schedule
from amsa_phys.engine.clock import MAX_EVENTS_PER_CYCLE
from amsa_phys.engine.delivery import Deliveries


@dataclass
class T:
    """A task as the compiler sees it: a name, a period and a timer phase in ticks."""

    path: str
    period: int
    phase: int = 0


def physics() -> None:
    """A hook (the physics step)."""


def other() -> None:
    """A second hook at another rate."""


def test_instants_list_what_is_due_in_order_tasks_log_hooks() -> None:
    a, b = T("A", 4), T("B", 6, phase=1)
    cycle, inst = schedule.instants([a, b], log_period=3, hooks=[(1, physics)])
    assert cycle == 12  # lcm of 4, 6, 3 and 1
    assert [i.offset for i in inst] == list(range(12))  # the physics is due at every tick
    due = {i.offset: ([t.path for t in i.tasks], i.log) for i in inst}
    assert due[0] == (["A"], True)
    assert due[1] == (["B"], False)  # B's timer phase
    assert due[4] == (["A"], False)
    assert due[7] == (["B"], False)
    assert due[6] == ([], True)
    assert all(i.hooks == [physics] for i in inst)


def test_tasks_at_one_instant_keep_the_execution_order_given() -> None:
    _, inst = schedule.instants([T("Z", 2), T("A", 1)], log_period=2, hooks=[])
    assert [t.path for t in inst[0].tasks] == ["Z", "A"]


def test_runs_fold_hook_only_instants_between_log_rows() -> None:
    # physics at every tick, a log row every 5: offsets 1-4 are physics only
    _, inst = schedule.instants([T("A", 10)], log_period=5, hooks=[(1, physics)])
    table = schedule.runs(inst)
    assert [(e[0], e[4], e[5]) for e in table] == [(0, 0, 1), (1, 4, 1), (5, 5, 1), (6, 9, 1)]
    assert [bool(e[1]) for e in table] == [True, False, False, False]
    assert [e[2] for e in table] == [True, False, True, False]


def test_runs_keep_apart_instants_with_different_hooks_or_spacing() -> None:
    _, inst = schedule.instants([], log_period=12, hooks=[(2, physics), (3, other)])
    table = schedule.runs(inst)
    # every listed instant once, in order, and a folded run only over equal hooks
    covered = [t for off, _, _, _, last, sp in table for t in range(off, last + 1, sp)]
    assert covered == [i.offset for i in inst]
    for off, _, _, hooks, last, sp in table:
        run = [i for i in inst if i.offset in range(off, last + 1, sp)]
        assert all(tuple(i.hooks) == hooks for i in run)


def test_too_many_events_per_cycle_is_refused() -> None:
    with pytest.raises(schedule.TooManyEvents) as info:
        schedule.instants([T("A", 1), T("B", MAX_EVENTS_PER_CYCLE + 7)], log_period=1, hooks=[])
    assert info.value.count > MAX_EVENTS_PER_CYCLE


def test_next_tick_finds_the_next_due_instant_across_cycles() -> None:
    _, inst = schedule.instants([T("A", 5, phase=2)], log_period=5, hooks=[])
    table = schedule.runs(inst)  # offsets 0 (log) and 2 (A), cycle 5
    assert [schedule.next_tick(table, 5, c) for c in (0, 1, 2, 3, 5, 6, 8)] == [
        0,
        2,
        2,
        5,
        5,
        7,
        10,
    ]


def test_deliveries_arrive_by_due_tick_then_send_order() -> None:
    heap = Deliveries()
    assert not heap
    heap.push(9, [("A.x", 1.0)])
    heap.push(4, [("A.x", 2.0), ("B.y", 5.0)])
    heap.push(4, [("A.x", 3.0)])  # due at the same tick, sent later: wins
    assert heap.next_due() == 4
    assert heap.in_flight("A.x") == 3
    values = {"A.x": 0.0, "B.y": 0.0}
    heap.deliver(3, values)
    assert values == {"A.x": 0.0, "B.y": 0.0}
    heap.deliver(8, values)
    assert values == {"A.x": 3.0, "B.y": 5.0}
    assert (heap.next_due(), heap.in_flight("A.x")) == (9, 1)
    heap.deliver(9, values)
    assert values["A.x"] == 1.0
    assert not heap


def test_a_groups_publication_arrives_as_whole_columns_in_send_order() -> None:
    from array import array

    import numpy as np

    data = array("d", [0.0] * 8)  # the store's two views of one memory (engine/store.py)
    col = np.frombuffer(data)
    heap = Deliveries()
    heap.push(2, [(slice(0, 8, 2), np.array([1.0, 2.0, 3.0, 4.0]))])  # a group's column
    heap.push(2, [(4, 9.0)])  # a scalar publication due at the same tick, sent later: wins
    heap.push(3, [(np.array([1, 7]), np.array([5.0, 6.0]))])  # the published rows only
    assert heap.in_flight(4) == 2
    assert heap.in_flight(7) == 1
    assert heap.in_flight(3) == 0
    heap.deliver(2, data, col)
    assert data.tolist() == [1.0, 0.0, 2.0, 0.0, 9.0, 0.0, 4.0, 0.0]
    heap.deliver(3, data, col)
    assert (data[1], data[7]) == (5.0, 6.0)
    assert not heap


def test_gauss_markov_factors_are_remembered_read_only_and_equal_the_scalar_ones() -> None:
    import numpy as np

    from amsa_phys.engine import noise

    sigma = np.array([0.1, 0.2, 0.1])
    tau = np.array([10.0, 0.0, 10.0])
    phi, q = noise.gauss_markov_many(sigma, tau, 0.25)
    for k in range(3):
        assert (phi[k], q[k]) == noise.gauss_markov(sigma[k], tau[k], 0.25)  # to the bit
    again = noise.gauss_markov_many(sigma.copy(), tau.copy(), 0.25)
    assert again[0] is phi  # the same values: the answer remembered
    assert not phi.flags.writeable  # so no caller can edit what others share
    other = noise.gauss_markov_many(sigma, tau, 0.5)
    assert other[0][0] != phi[0]  # another period, another answer
