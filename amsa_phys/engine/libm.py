"""libm's own transcendental functions over arrays, for array steps that must equal scalar ones.

A component's ``step_many`` (``engine/batch.py``) stands for its scalar ``do_step`` run copy by
copy, and a batched sweep's rows must equal the runs made alone. numpy's SIMD versions of some
functions round differently from libm in the last bit, which Python's ``math`` calls: measured
here on 200,000 random arguments, ``np.arctan2`` differed from ``math.atan2`` in 7.7 % of them,
``np.exp`` in 4.6 %, ``np.hypot`` in 0.6 %, ``np.expm1`` too (``sin``, ``cos`` and ``sqrt``
matched every one). A last-bit difference in a controller's angle grows into a 7e-14 difference
of a sweep's metrics (found by a user comparing ``--executor batch`` with ``local``). These
helpers apply the ``math`` function element by element: ~0.1 µs an element, against a component
step of the copies' other arithmetic, and the arrays here hold one value per copy. ``exp`` and
``expm1`` take parameters that the copies mostly share (a 1,000-car platoon's Gauss–Markov
factors), so they map each distinct value once.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["atan2", "exp", "expm1", "hypot", "hypot_exceeds"]


def _map2(fn, a: np.ndarray, b: np.ndarray) -> np.ndarray:  # type: ignore[no-untyped-def]
    if (  # a group's two columns (the usual call): no broadcast, ravel or reshape to make
        type(a) is np.ndarray
        and type(b) is np.ndarray
        and a.ndim == 1
        and a.shape == b.shape
        and a.dtype == np.float64
        and b.dtype == np.float64
    ):
        return np.fromiter(map(fn, a.tolist(), b.tolist()), np.float64, a.size)
    a, b = np.broadcast_arrays(np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64))
    out = np.fromiter(map(fn, a.ravel().tolist(), b.ravel().tolist()), np.float64, a.size)
    return out.reshape(a.shape)


def _map1(fn, a: np.ndarray) -> np.ndarray:  # type: ignore[no-untyped-def]
    a = np.asarray(a, dtype=np.float64)
    if a.size > 16:  # usually a parameter shared by the copies: each distinct value once
        values, where = np.unique(a.ravel(), return_inverse=True)
        mapped = np.fromiter(map(fn, values.tolist()), np.float64, values.size)
        return mapped[where].reshape(a.shape)
    return np.fromiter(map(fn, a.ravel().tolist()), np.float64, a.size).reshape(a.shape)


def atan2(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``math.atan2`` element by element."""
    return _map2(math.atan2, y, x)


def hypot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``math.hypot`` element by element."""
    return _map2(math.hypot, x, y)


def hypot_exceeds(x: np.ndarray, y: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """``math.hypot(x, y) > limit`` element by element: the same booleans as :func:`hypot`'s.

    Why: a comparison needs ``math``'s bits only where they could decide it. numpy's
    ``hypot`` is within an ulp or two of ``math.hypot`` (both are accurate to under an ulp),
    so it decides every element farther than 1e-12 (relative) from ``limit``; the rest, and
    anything not finite, are computed by :func:`hypot`. A 1,000-car platoon's controller
    asks this of every car at every step (~50 µs instead of ~120).
    """
    x, y, limit = np.broadcast_arrays(
        np.asarray(x, dtype=np.float64),
        np.asarray(y, dtype=np.float64),
        np.asarray(limit, dtype=np.float64),
    )
    h = np.hypot(x, y)
    out = h > limit
    near = ~(np.abs(h - limit) > 1e-12 * np.abs(limit))  # NaN and inf land here too
    if near.any():
        out[near] = hypot(x[near], y[near]) > limit[near]
    return out


def exp(x: np.ndarray) -> np.ndarray:
    """``math.exp`` element by element (overflow gives inf, as numpy's does)."""
    return _map1(_exp, x)


def expm1(x: np.ndarray) -> np.ndarray:
    """``math.expm1`` element by element."""
    return _map1(_expm1, x)


def _exp(v: float) -> float:
    try:
        return math.exp(v)
    except OverflowError:
        return math.inf


def _expm1(v: float) -> float:
    try:
        return math.expm1(v)
    except OverflowError:
        return math.inf
