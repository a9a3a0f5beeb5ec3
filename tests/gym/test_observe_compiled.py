"""The single env's observation in C (``_kernels.observe_one``) is ``Observer.of_values``'s,
bit for bit, and the Python method's wherever C does not take the inputs (its errors too)."""

from __future__ import annotations

import importlib.util
import math
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine import publish
from amsa_phys.gym.observe import Observer
from amsa_phys.model.template import Port

#: built, and not switched off (``AMSA_PHYS_PURE=1``: the Python paths alone run)
BUILT = (
    importlib.util.find_spec("amsa_phys.engine._kernels") is not None
    and publish._extension("_kernels") is not None
)
pytestmark = pytest.mark.skipif(
    not BUILT, reason="the extension was not built (no C compiler), or the pure path was asked for"
)

#: the follower controller's ports, then every unit the observer tells apart
FOLLOWER = [
    Port("xLeader", unit="m"),
    Port("yLeader", unit="m"),
    Port("xFollower", unit="m"),
    Port("yFollower", unit="m"),
    Port("headingFollower", unit="rad"),
    Port("distanceLeaderFollower", unit="m"),
]
EVERY_UNIT = [
    *FOLLOWER,
    Port("xGoal", unit="m"),
    Port("yGoal", unit="m"),
    Port("speed", unit="m/s"),
    Port("bearing", unit="rad"),
    Port("power", unit="%"),
]
NO_OWN = [Port("speed", unit="m/s"), Port("bearing", unit="rad"), Port("gap", unit="m")]
SPECIAL = [
    0.0,
    -0.0,
    1e-300,
    5e-324,
    49.99999999,
    50.0,
    50.000001,
    -50.0,
    1e308,
    -1e308,
    math.pi,
    -math.pi,
    3 * math.pi,
    float("nan"),
    float("inf"),
    float("-inf"),
]


def _both(ports: list[Port], values: list[Any], **kw: Any) -> tuple[Any, Any]:
    """What the compiled and the Python observation give (an array's bytes, or the error)."""
    out = []
    for compiled in (True, False):
        observer = Observer(ports, **kw)
        assert (observer._one is not None) is True
        if not compiled:
            observer._one = None
        try:
            got = observer.of_values(values)
            out.append((got.dtype, got.shape, got.flags.writeable, got.tobytes()))
        except Exception as exc:  # the same error is the point
            out.append(repr(exc))
    return out[0], out[1]


@pytest.mark.parametrize(
    "ports", [FOLLOWER, EVERY_UNIT, NO_OWN], ids=["follower", "units", "no-own"]
)
def test_random_and_special_inputs_give_the_python_observation(ports: list[Port]) -> None:
    rng = np.random.default_rng(7)
    n = len(ports)
    for k in range(600):
        values = (rng.normal(0, 10 ** rng.integers(0, 4), n)).tolist()
        if k % 3 == 0:  # special values at random places (the heading's inf: math raises)
            for i in rng.integers(0, n, 2).tolist():
                values[i] = SPECIAL[int(rng.integers(0, len(SPECIAL)))]
        got, want = _both(ports, values)
        assert got == want, values
        got, want = _both(ports, tuple(values), range_m=7.5, speed_mps=0.5)
        assert got == want, values


def test_the_values_are_the_documented_ones() -> None:
    """Not only alike: a leader 10 m ahead of a follower facing +y is forward 10 / range_m,
    left 0; 1000 m ahead clips to 1, a NaN to -1."""
    observer = Observer(FOLLOWER, range_m=20.0)
    obs = observer.of_values([3.0, 14.0, 3.0, 4.0, math.pi / 2, 10.0])
    assert obs[0] == pytest.approx(0.5)
    assert obs[1] == pytest.approx(0.0, abs=1e-15)
    assert obs[2] == 0.5
    assert observer.of_values([1000.0, 0.0, 0.0, 0.0, 0.0, float("nan")]).tolist() == [
        1.0,
        0.0,
        -1.0,
    ]


@pytest.mark.parametrize(
    ("values", "kw"),
    [
        ([1, 2.0, 3.0, 4.0, 0.5, 6.0], {}),  # an int: the Python method takes it
        ([1.0, 2.0, 3.0, 4.0, float("inf"), 6.0], {}),  # math.cos(inf): ValueError
        ([1.0, 2.0, 3.0, 4.0, 0.5, 6.0], {"range_m": 0.0}),  # ZeroDivisionError
        ([1.0, 2.0, 3.0, 4.0, 0.5, 6.0], {"range_m": 20}),  # an int scale
        ([np.float64(1.0), 2.0, 3.0, 4.0, 0.5, 6.0], {}),  # a numpy float
    ],
)
def test_what_c_does_not_take_goes_to_python(values: list[Any], kw: dict[str, Any]) -> None:
    got, want = _both(FOLLOWER, values, **kw)
    assert got == want
