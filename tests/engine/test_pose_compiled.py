"""A robot's pose outputs computed in C (``_publish.pose``) are the Python pose's dict, bit
for bit: the heading wrapped with Python's float ``%``, the speed with libm's cos and sin."""

from __future__ import annotations

import math
import struct
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine import publish
from amsa_phys.physics.robots import Robot

compiled = publish.pose()
pytestmark = pytest.mark.skipif(compiled is None, reason="the _publish extension is not built")


def robot(kin: Any, rims: Any, c_pose: Any) -> Any:
    rover = SimpleNamespace(_source=lambda: kin, _rims=lambda: rims)
    return SimpleNamespace(rover=rover, _c_pose=c_pose)


def bits(pose: dict[str, float]) -> list[tuple[str, bytes]]:
    return [(k, struct.pack("<d", v)) for k, v in pose.items()]


ODD = [0.0, -0.0, math.pi, -math.pi, 2 * math.pi, -2 * math.pi, 1e300, -1e-300, 7.5, -7.5]


def test_the_same_dict_bit_for_bit() -> None:
    rng = np.random.default_rng(3)
    cases = [[float(v) for v in rng.normal(0, s, 6)] for s in (1.0, 10.0, 1e4) for _ in range(300)]
    cases += [[1.0, 2.0, a, 0.5, -0.25, 0.1] for a in ODD]
    cases += [[1.0, 2.0, 0.5, v, -v, v] for v in (math.inf, -math.inf, math.nan)]
    for kin in cases:
        for rims in ((0.5, -0.5), [1.25, 3.0]):
            fast = Robot._pose(robot(kin, rims, compiled))
            slow = Robot._pose(robot(kin, rims, None))
            assert list(fast) == list(slow)  # the same keys in the same order
            assert bits(fast) == bits(slow), kin


def test_anything_but_floats_is_left_to_python() -> None:
    assert compiled(lambda: [1, 2.0, 0.5, 1.0, 0.0, 0.0], lambda: (0.0, 0.0)) is None
    assert compiled(lambda: [1.0] * 5, lambda: (0.0, 0.0)) is None
    assert compiled(lambda: [1.0] * 6, lambda: (0.0,)) is None
    assert compiled(lambda: [1.0] * 6, lambda: (np.float64(1.0), 0.0)) is None
    # the Python pose then computes from the ints as it always did
    pose = Robot._pose(robot([1, 2, 0, 3, 0, 0], (0.0, 0.0), compiled))
    assert pose["posX"] == 1
    assert pose["speed"] == 3.0


def test_an_infinite_angle_raises_as_the_python_pose_does() -> None:
    for a in (math.inf, -math.inf):
        assert compiled(lambda a=a: [1.0, 2.0, a, 0.5, -0.25, 0.1], lambda: (0.0, 0.0)) is None
        with pytest.raises(ValueError, match="math domain error"):
            Robot._pose(robot([1.0, 2.0, a, 0.5, -0.25, 0.1], (0.0, 0.0), compiled))
    nan = Robot._pose(robot([1.0, 2.0, math.nan, 0.5, -0.25, 0.1], (0.0, 0.0), compiled))
    assert math.isnan(nan["heading"])


def test_a_reader_that_raises_raises() -> None:
    def broken() -> list[float]:
        raise RuntimeError("no state")

    with pytest.raises(RuntimeError, match="no state"):
        compiled(broken, lambda: (0.0, 0.0))
