"""The vector env's observations (``Observer.of_rows``) are the single env's, row by row."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym.observe import Observer
from amsa_phys.model.template import Port

PORTS = [
    Port("xLeader", 0.0, "", "m"),
    Port("yLeader", 0.0, "", "m"),
    Port("xFollower", 0.0, "", "m"),
    Port("yFollower", 0.0, "", "m"),
    Port("headingFollower", 0.0, "", "rad"),
    Port("distanceLeaderFollower", 0.0, "", "m"),
    Port("speed", 0.0, "", "m/s"),
    Port("bearing", 0.0, "", "rad"),
    Port("load", 0.0, "", "%"),
]


def rows(n: int = 4000) -> np.ndarray:
    """Random inputs at every scale, with the edge cases among them: values at and just
    beyond the clip, huge values and negative angles (finite: the engine refuses a
    non-finite output, so no component ever reads one)."""
    rng = np.random.default_rng(3)
    out = rng.normal(0, 1, (n, len(PORTS))) * rng.choice([1e-3, 1, 40, 60, 1e4], (n, len(PORTS)))
    special = [50.0, -50.0, 50.000000000001, -49.99999999999, 1e300, -7 * np.pi, 0.0, -0.0]
    mask = rng.random(out.shape) < 0.05
    out[mask] = rng.choice(special, mask.sum())
    return out


@pytest.mark.parametrize("mode", ["relative", "absolute"])
def test_rows_at_once_are_the_rows_one_by_one_bit_for_bit(mode: str) -> None:
    observer = Observer(PORTS, mode)
    raw = rows()
    many = observer.of_rows(raw)
    one = np.stack([observer(row) for row in raw])
    assert many.shape == one.shape
    assert many.dtype == np.float64
    assert many.tobytes() == one.tobytes()  # bit for bit (-0.0 too)
    if mode == "relative":
        assert (np.abs(many) <= 1.0).all()
        assert (np.abs(many) == 1.0).any()  # the clip was exercised
    assert not np.shares_memory(many, raw)
