"""The STL monitor's sliding window (``stl/monitor._window``, ``_past``) equals its definition:
``out[i]`` is the min (max) of ``s[i+a .. i+b]``, samples past the end counting as ``fill``;
for windows shorter, as long as, and far longer than the run, and ones starting after it."""

from __future__ import annotations

import numpy as np
import pytest

from amsa_phys.stl.monitor import _past, _window


def _naive(s: np.ndarray, a: int, b: int, fill: float, fn: np.ufunc) -> np.ndarray:
    n = s.shape[0]
    out = np.empty_like(s)
    for i in range(n):
        window = [s[j] if j < n else np.full(s.shape[1:], fill) for j in range(i + a, i + b + 1)]
        out[i] = fn.reduce(np.array(window), axis=0)
    return out


@pytest.mark.parametrize("n", [1, 2, 7, 30])
@pytest.mark.parametrize(
    ("a", "b"), [(0, 0), (0, 1), (0, 5), (2, 3), (3, 11), (0, 40), (6, 45), (29, 29), (31, 60)]
)
@pytest.mark.parametrize(("fn", "fill"), [(np.minimum, np.inf), (np.maximum, -np.inf)])
def test_window_is_its_definition(n: int, a: int, b: int, fn: np.ufunc, fill: float) -> None:
    rng = np.random.default_rng(n * 1000 + a * 31 + b)
    s = rng.normal(size=(n, 3))
    np.testing.assert_array_equal(_window(s, a, b, fill, fn), _naive(s, a, b, fill, fn))
    past = _past(s, a, b, fill, fn)
    np.testing.assert_array_equal(past, _naive(s[::-1], a, b, fill, fn)[::-1])
    assert past.dtype == np.float64
