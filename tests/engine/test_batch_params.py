"""A group's parameters as arrays (``engine/batch.ParamArrays``): built once, kept until a
member's parameter changes, then built again from the members' new values."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from amsa_phys.engine.batch import ParamArrays


def _members(*kv: float) -> list[SimpleNamespace]:
    return [SimpleNamespace(p=SimpleNamespace(Kv=k, Kw=2 * k)) for k in kv]


def test_each_parameter_is_the_members_values_in_order() -> None:
    p = ParamArrays(_members(0.1, 0.2, 0.3))
    np.testing.assert_array_equal(p.Kv, [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(p.Kw, [0.2, 0.4, 0.6])
    assert p.Kv.dtype == np.float64


def test_an_array_is_built_once_and_kept() -> None:
    members = _members(0.1, 0.2)
    p = ParamArrays(members)
    first = p.Kv
    members[0].p.Kv = 9.0  # not yet told: the array stays what it was
    assert p.Kv is first
    np.testing.assert_array_equal(p.Kv, [0.1, 0.2])


def test_invalidate_makes_every_parameter_read_the_members_again() -> None:
    members = _members(0.1, 0.2)
    p = ParamArrays(members)
    _ = p.Kv, p.Kw
    members[1].p.Kv = 5.0
    members[0].p.Kw = -1.0
    p.invalidate()
    np.testing.assert_array_equal(p.Kv, [0.1, 5.0])
    np.testing.assert_array_equal(p.Kw, [-1.0, 0.4])
    members[0].p.Kv = 7.0
    p.invalidate()
    p.invalidate()  # twice is harmless
    np.testing.assert_array_equal(p.Kv, [7.0, 5.0])


def test_an_unknown_parameter_is_an_attribute_error() -> None:
    p = ParamArrays(_members(0.1))
    try:
        _ = p.nope
    except AttributeError:
        pass
    else:
        raise AssertionError("p.nope should raise AttributeError")
    assert not hasattr(p, "__deepcopy__")
