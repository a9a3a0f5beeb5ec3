"""Rovers fold once per kind (``forces.per_kind``): the constants a 1,000-car platoon's
compiled fleet starts with are folded for one car, not a thousand, and still each rover's
own. Held here: every rover's plan row equals :func:`compiled.plan_row` of that rover, and
rovers that differ in any parameter, even only in the sign of a zero, do not share a row."""

from __future__ import annotations

import dataclasses

from regimes import DT, make_rovers

from amsa_phys.physics import compiled
from amsa_phys.physics.forces import fold_key, per_kind


def test_plan_rows_are_each_rovers_own_and_shared_only_between_equal_rovers() -> None:
    _, rovers = make_rovers(6)
    _, others = make_rovers(3, stallForce=60.0)
    odd = others[2]  # differs from others[1] only in the sign of a zero
    others[1].wheel = dataclasses.replace(odd.wheel, com_height_m=0.0)
    odd.wheel = dataclasses.replace(odd.wheel, com_height_m=-0.0)
    every = [*rovers, *others]
    rows = compiled.plan_rows(every, DT)
    assert rows == [compiled.plan_row(r, DT) for r in every]
    assert all(rows[k] is rows[0] for k in range(6))  # identical cars: folded once
    assert rows[6] != rows[0]  # another motor
    assert rows[8] is not rows[7]  # -0.0 and 0.0 fold apart
    assert fold_key(odd) != fold_key(others[1])


def test_per_kind_calls_once_per_distinct_rover() -> None:
    _, rovers = make_rovers(5)
    _, heavy = make_rovers(2)
    for r in heavy:
        r.mass = 45.0
    calls = []
    out = per_kind([*rovers, *heavy], lambda r: calls.append(r.name) or r.name)
    assert calls == ["R0", "R0"]  # one call for the light rovers, one for the heavy
    assert out == ["R0"] * 7
