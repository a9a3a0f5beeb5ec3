"""A group's outputs are checked for non-finite values in one call in the usual case
(``engine/batch.first_bad``); the quick check must never let a NaN or an infinity through,
nor call huge finite values bad."""

from __future__ import annotations

import numpy as np
import pytest

from amsa_phys.engine.batch import first_bad


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("at", [0, 5, 999])
def test_a_non_finite_value_is_found_where_it_is(bad: float, at: int) -> None:
    arr = np.linspace(-3.0, 3.0, 1000)
    arr[at] = bad
    assert first_bad(arr, None) == at


def test_the_first_of_several_is_named() -> None:
    arr = np.zeros(10)
    arr[[7, 3, 8]] = [np.inf, np.nan, -np.inf]
    assert first_bad(arr, None) == 3


def test_huge_finite_values_are_good() -> None:
    """Their squares overflow the quick check's sum: the exact check must clear them."""
    arr = np.array([1e200, -1e300, 1.7976931348623157e308, 0.0])
    assert first_bad(arr, None) is None
    arr[2] = np.nan
    assert first_bad(arr, None) == 2


def test_finite_values_and_an_empty_group_are_good() -> None:
    assert first_bad(np.array([0.0, -0.0, 5e-324, -1.0]), None) is None
    assert first_bad(np.zeros(0), None) is None


def test_only_published_rows_count() -> None:
    arr = np.array([np.nan, 1.0, np.inf, 2.0])
    assert first_bad(arr, np.array([False, True, False, True])) is None
    assert first_bad(arr, np.array([False, True, True, True])) == 2


def test_a_broadcast_view_is_checked_like_a_copy() -> None:
    """A template may return one number for every copy (``step_group`` broadcasts it)."""
    assert first_bad(np.broadcast_to(np.float64(np.nan), (4,)), None) == 0
    assert first_bad(np.broadcast_to(np.float64(2.0), (4,)), None) is None


def test_huge_finite_values_raise_no_warning_a_user_would_see() -> None:
    """The quick check's overflow is expected: a run with huge values prints no numpy warning."""
    import warnings

    with warnings.catch_warnings(record=True) as seen:
        assert first_bad(np.array([1e200, 2.0]), None) is None
    assert [str(w.message) for w in seen] == []
