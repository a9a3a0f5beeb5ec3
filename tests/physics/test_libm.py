"""engine/libm.py: array functions that give libm's (Python ``math``'s) bits, element by
element, so array steps equal scalar ones."""

from __future__ import annotations

import math

import numpy as np

from amsa_phys.engine import libm


def test_each_element_is_maths_own() -> None:
    rng = np.random.default_rng(3)
    x = rng.uniform(-50, 50, 20_000)
    y = rng.uniform(-50, 50, 20_000)
    assert libm.atan2(y, x).tolist() == [math.atan2(b, a) for a, b in zip(x, y, strict=True)]
    assert libm.hypot(x, y).tolist() == [math.hypot(a, b) for a, b in zip(x, y, strict=True)]
    assert libm.exp(x / 10).tolist() == [math.exp(a / 10) for a in x]
    assert libm.expm1(x / 10).tolist() == [math.expm1(a / 10) for a in x]


def test_shapes_broadcast_and_overflow_is_inf() -> None:
    assert libm.hypot(np.array([[3.0], [6.0]]), np.array([4.0, 8.0])).shape == (2, 2)
    assert libm.exp(np.array([1000.0])).tolist() == [math.inf]
    assert libm.atan2(np.array([]), np.array([])).shape == (0,)


def test_hypot_exceeds_gives_maths_verdict_even_at_the_limit() -> None:
    """Limits at math.hypot's own value and one ulp either side (where numpy's hypot may
    round the other way), zero, inf and NaN: the verdicts of ``math.hypot(x, y) > limit``."""
    rng = np.random.default_rng(8)
    x = rng.uniform(-50, 50, 20_000)
    y = rng.uniform(-50, 50, 20_000)
    exact = np.array([math.hypot(a, b) for a, b in zip(x, y, strict=True)])
    for limit in (exact, np.nextafter(exact, 0), np.nextafter(exact, np.inf), exact * 0.5):
        expected = [math.hypot(a, b) > c for a, b, c in zip(x, y, limit, strict=True)]
        assert libm.hypot_exceeds(x, y, limit).tolist() == expected
    odd = np.array([0.0, 0.0, math.inf, math.nan, 3.0, -0.0])
    other = np.array([0.0, 1e-320, 1.0, 1.0, 4.0, 0.0])
    limit = np.array([0.0, 0.0, 1e308, 0.0, math.inf, -0.0])
    expected = [math.hypot(a, b) > c for a, b, c in zip(odd, other, limit, strict=True)]
    assert libm.hypot_exceeds(odd, other, limit).tolist() == expected
    assert (np.hypot(x, y) != exact).any()  # numpy's does differ somewhere: the test can fail
