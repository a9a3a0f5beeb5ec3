"""A random leader group's steering in C (``_step.steer_random``) gives the floats of the
numpy arithmetic it replaces in ``FreeRobot._random_many`` and of the scalar steering a run
alone takes (``FreeRobot._behaviour``: Python's ``%`` and ``math.cos``): on ordinary
headings and on the edges (errors at ±pi, multiples of 2 pi, signed zeros, huge angles,
NaN and infinity, a cosine at or below zero)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from amsa_phys.physics import compiled
from amsa_phys.physics.step_path import extension

#: the C function's arguments, as its errors name them
NAMES = ("heading", "angle", "cruise", "factor", "gain", "left", "right")

pytestmark = pytest.mark.skipif(
    extension() is None or not compiled.columns_compiled(),
    reason="the compiled step was not built (no C compiler at install)",
)


def in_numpy(heading, angle, cruise, factor, gain):  # type: ignore[no-untyped-def]
    """``FreeRobot._random_many``'s numpy arithmetic."""
    with np.errstate(all="ignore"):
        power = cruise * factor
        err = (heading - angle + math.pi) % (2 * math.pi) - math.pi
        diff = gain * err
        cos = np.fromiter(map(math.cos, err.tolist()), dtype=np.float64, count=len(err))
        forward = power * np.where(cos > 0.0, cos, 0.0)
        return forward - diff, forward + diff


def alone(heading: float, angle: float, cruise: float, factor: float, gain: float):  # type: ignore[no-untyped-def]
    """``FreeRobot._behaviour``'s scalar steering (behaviour 4), as a run alone takes it."""
    err = (heading - angle + math.pi) % (2 * math.pi) - math.pi
    diff = gain * err
    cos = math.cos(err)
    forward = cruise * factor * (cos if cos > 0.0 else 0.0)
    return forward - diff, forward + diff


def cases() -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(3)
    pi = math.pi
    edges = [0.0, -0.0, pi, -pi, 2 * pi, -2 * pi, 3 * pi, pi / 2, -pi / 2, 1e-300, 1e16]
    edges += [1e300, -1e300, math.nextafter(pi, 0), math.nextafter(-pi, 0), 100.5 * pi]
    heading = [*edges, *rng.uniform(-50, 50, 500), *rng.normal(0, 1e6, 50)]
    angle = [0.0] * len(edges) + list(rng.uniform(-50, 50, 550))
    heading += [math.nan, math.inf, -math.inf, 1.0]
    angle += [0.0, 0.0, 1.0, math.nan]
    n = len(heading)
    cruise = rng.uniform(0, 100, n)
    cruise[:4] = [0.0, -0.0, 100.0, 1e-320]
    factor = rng.uniform(0.5, 1.2, n)
    gain = rng.uniform(0, 1000, n)
    gain[5] = 0.0
    f64 = np.float64
    return (np.array(heading, f64), np.array(angle, f64), cruise, factor, gain)


def test_the_c_steering_is_the_numpy_and_the_scalar_steering_bit_for_bit() -> None:
    from amsa_phys.physics import _step  # type: ignore[attr-defined]

    heading, angle, cruise, factor, gain = cases()
    left, right = np.empty(len(heading)), np.empty(len(heading))
    _step.steer_random(heading, angle, cruise, factor, gain, left, right)
    nl, nr = in_numpy(heading, angle, cruise, factor, gain)
    assert left.tobytes() == nl.tobytes()
    assert right.tobytes() == nr.tobytes()
    finite = np.isfinite(heading) & np.isfinite(angle)
    for k in np.flatnonzero(finite).tolist():
        sl, sr = alone(heading[k], angle[k], cruise[k], factor[k], gain[k])
        assert np.float64(sl).tobytes() == left[k].tobytes(), k
        assert np.float64(sr).tobytes() == right[k].tobytes(), k
    # the cases reach both sides of the cosine's cut and the wrap
    err = (heading[finite] - angle[finite] + math.pi) % (2 * math.pi) - math.pi
    assert (np.cos(err) <= 0).any()
    assert (np.cos(err) > 0).any()


def test_the_c_steering_refuses_arrays_it_would_read_out_of_bounds() -> None:
    from amsa_phys.physics import _step  # type: ignore[attr-defined]

    ok = [np.zeros(3) for _ in range(7)]
    _step.steer_random(*ok)
    for k, bad in ((2, np.zeros(2)), (4, np.zeros(3, dtype=np.float32)), (6, np.zeros(4))):
        args = list(ok)
        args[k] = bad
        with pytest.raises(ValueError, match=f"{NAMES[k]}: .*float64 items"):
            _step.steer_random(*args)
