"""A robot group's pose outputs in C (``_step.robot_poses``) are the floats of the numpy
arithmetic they replace in ``ControlledRobot.step_many`` and of the scalar pose a run alone
publishes (``Robot._pose``: Python's ``%``, ``math.cos`` and ``math.sin``), taken from the
right rows of the state and rims, for angles of every size and sign and at the wrap."""

from __future__ import annotations

import math

import numpy as np
import pytest

from amsa_phys.physics import compiled
from amsa_phys.physics.robots import POSE_NAMES
from amsa_phys.physics.step_path import extension

pytestmark = pytest.mark.skipif(
    extension() is None or not compiled.columns_compiled(),
    reason="the compiled step was not built (no C compiler at install)",
)


def rovers() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(N, 6) states, (2, N) rims and an index that skips, repeats and reorders rows."""
    rng = np.random.default_rng(11)
    n = 400
    state = rng.normal(0, 20, (n, 6))
    pi = math.pi
    edges = [0.0, -0.0, pi, -pi, 3 * pi, -3 * pi, 2 * pi, 1e-300, 1e15, -1e15, 1e300]
    state[: len(edges), 2] = edges
    state[len(edges) : 200, 2] = np.ldexp(
        rng.uniform(-1, 1, 200 - len(edges)), rng.integers(-30, 30, 200 - len(edges))
    )
    rims = rng.normal(0, 3, (2, n))
    index = np.concatenate([np.arange(n)[::-1], [5, 5, 0]]).astype(np.int64)
    return state, rims, index


def test_the_c_poses_are_the_numpy_and_the_scalar_poses_bit_for_bit() -> None:
    from amsa_phys.physics import _step  # type: ignore[attr-defined]

    state, rims, index = rovers()
    out = np.empty((7, len(index)))
    _step.robot_poses(state, rims, index, out)
    x, y, a, vx, vy, w = state[index].T
    left, right = rims[:, index]
    numpy_path = {
        "posX": x,
        "posY": y,
        "heading": (a + math.pi) % (2 * math.pi) - math.pi,
        "speed": vx * np.cos(a) + vy * np.sin(a),
        "yawRate": w,
        "wheelSpeedL": left,
        "wheelSpeedR": right,
    }
    for row, name in zip(out, POSE_NAMES, strict=True):
        assert row.tobytes() == numpy_path[name].tobytes(), name
    for j, k in enumerate(index.tolist()):
        x, y, a, vx, vy, w = state[k].tolist()
        scalar = [x, y, (a + math.pi) % (2 * math.pi) - math.pi]
        scalar += [vx * math.cos(a) + vy * math.sin(a), w, rims[0, k], rims[1, k]]
        assert out[:, j].tobytes() == np.array(scalar).tobytes(), (j, k)


def test_the_c_poses_refuse_an_index_out_of_range() -> None:
    from amsa_phys.physics import _step  # type: ignore[attr-defined]

    state, rims, _ = rovers()
    for bad in (-1, len(state)):
        with pytest.raises(IndexError, match="out of range"):
            _step.robot_poses(state, rims, np.array([0, bad], dtype=np.int64), np.empty((7, 2)))
    with pytest.raises(ValueError, match=r"rims \(2, N\)"):
        _step.robot_poses(state, rims[:, :-1].copy(), np.zeros(1, np.int64), np.empty((7, 1)))
