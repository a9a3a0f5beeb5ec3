"""The Timeline (model/timeline.py): the one flattening of phases into changes at instants."""

from __future__ import annotations

from fractions import Fraction as F

from amsa_phys.model.scenario import Change, Phase, Step
from amsa_phys.model.timeline import Timeline


def _c(param: str, value: float) -> Change:
    return Change("Ctl", param, value)


def _timeline() -> Timeline:
    """Phase 0 (Kv=1), a step at 5 (Kw=2), phase 1 at 10 (Kv=3), a step at 15 (Kv=4)."""
    return Timeline.of(
        [
            Phase(F(0), [_c("Kv", 1)], within=[Step(F(5), [_c("Kw", 2)], "w", entry=0)]),
            Phase(F(10), [_c("Kv", 3)], "slow", within=[Step(F(15), [_c("Kv", 4)])], entry=1),
        ],
        F(20),
    )


def test_points_are_every_later_change_in_time_order_with_their_phase() -> None:
    pts = _timeline().points()
    assert [(p.at, p.phase, p.starts_phase) for p in pts] == [
        (F(5), 0, False),
        (F(10), 1, True),
        (F(15), 1, False),
    ]
    assert [c.value for p in pts for c in p.changes] == [2, 3, 4]
    assert (pts[0].label, pts[0].entry, pts[1].label, pts[1].entry) == ("w", 0, "slow", 1)


def test_initial_is_phase_zero_and_not_a_point() -> None:
    tl = _timeline()
    assert [c.value for c in tl.initial] == [1]
    assert all(p.at > 0 for p in tl.points())
    # no phases at all: one empty phase 0
    empty = Timeline.of([], F(3))
    assert empty.initial == ()
    assert empty.points() == ()
    assert empty.starts == (F(0),)


def test_phase_at_holds_from_each_start_inclusive() -> None:
    tl = _timeline()
    assert [tl.phase_at(t) for t in (0, F(5), F(99, 10), 10, 19.5, 25)] == [0, 0, 0, 1, 1, 1]


def test_cut_drops_later_changes_and_remembers_the_plan() -> None:
    tl = _timeline()
    cut = tl.cut(F(12))
    assert cut.duration == 12
    assert cut.is_cut
    assert [p.at for p in cut.points()] == [F(5), F(10)]  # the step at 15 dropped
    assert cut.bounds() == (0, 10, 20)  # the file's plan, not (0, 10, 12)
    # cut again: still the first plan
    assert tl.cut(F(12)).cut(F(7)).bounds() == (0, 10, 20)
    assert [p.at for p in tl.cut(F(7)).points()] == [F(5)]
    # the original is untouched (a cached scenario shares its phases with other runs)
    assert len(tl.phases[1].within) == 1
    assert [p.at for p in tl.points()] == [5, 10, 15]


def test_cut_at_a_change_instant_drops_it_and_a_longer_run_is_not_cut() -> None:
    tl = _timeline()
    assert [p.at for p in tl.cut(F(10)).points()] == [F(5)]  # a run ending at 10 stops there
    longer = tl.cut(F(30))
    assert not longer.is_cut
    assert longer.duration == 30
    assert longer.bounds() == (0, 10, 30)


def test_uncut_bounds_are_the_starts_then_the_duration() -> None:
    assert _timeline().bounds() == (0, 10, 20)


def test_changes_of_finds_a_key_in_starts_and_steps_before_a_time() -> None:
    tl = _timeline()
    assert tl.changes_of("Ctl.Kv") == (10, 15)
    assert tl.changes_of("Ctl.Kv", before=F(15)) == (10,)
    assert tl.changes_of("Ctl.Kw") == (5,)
    assert tl.changes_of("Ctl.other") == ()


def test_with_initial_adds_after_the_files_values_without_sharing() -> None:
    tl = _timeline()
    more = tl.with_initial([_c("Kw", 9)])
    assert [(c.param, c.value) for c in more.initial] == [("Kv", 1), ("Kw", 9)]
    assert [c.value for c in tl.initial] == [1]
    assert more.points() == tl.points()


def test_with_initial_drops_the_values_it_overrides() -> None:
    """A value set over the file's is listed once, with the value in force (a bag's phase-0
    event, a run's description): of one key given twice, the last."""
    tl = _timeline()
    more = tl.with_initial([_c("Kw", 2), _c("Kv", 9), _c("Kw", 3)])
    assert [(c.param, c.value) for c in more.initial] == [("Kw", 3), ("Kv", 9)]
    assert [c.value for c in tl.initial] == [1]


def test_phases_and_steps_are_frozen() -> None:
    import dataclasses

    import pytest

    tl = _timeline()
    with pytest.raises(dataclasses.FrozenInstanceError):
        tl.phases[1].at = F(11)  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        tl.phases[0].within[0].changes = []  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        tl.duration = F(1)  # type: ignore[misc]
