"""The vector env's observations in C (``_step.observe_rows``, the MDE controller's inputs:
positions, a heading, metres and speeds) are the single env's row by row and the numpy
path's, to the bit: random rows, and every edge (NaN, infinities, -0.0, huge headings,
values beyond the clip on both sides)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym.observe import Observer
from amsa_phys.model.template import Port
from amsa_phys.physics import compiled

pytestmark = pytest.mark.skipif(
    not compiled.columns_compiled(), reason="the compiled step was not built (no C compiler)"
)

MDE = [
    Port("xLeader", 0.0, "", "m"),
    Port("yLeader", 0.0, "", "m"),
    Port("xFollower", 0.0, "", "m"),
    Port("yFollower", 0.0, "", "m"),
    Port("headingFollower", 0.0, "", "rad"),
    Port("distanceLeaderFollower", 0.0, "", "m"),
]
#: two other rovers, a speed, and no own heading (everything divided, nothing rotated)
MORE = [*MDE[:4], Port("xCar", 0.0, "", "m"), Port("yCar", 0.0, "", "m"), MDE[4], MDE[5]]
MORE += [Port("speed", 0.0, "", "m/s")]
FLAT = [Port("distance", 0.0, "", "m"), Port("speed", 0.0, "", "m/s")]


def _rows(width: int, heading: int | None, n: int = 5000) -> np.ndarray:
    rng = np.random.default_rng(width)
    rows = rng.normal(0, 40, (n, width))
    if heading is not None:
        rows[:, heading] = rng.uniform(-1e4, 1e4, n) * rng.choice([1e-6, 1, 1e3], n)
    edges = [np.nan, np.inf, -np.inf, -0.0, 0.0, 50.0, -50.0, 1e300, -1e300, 5e-324]
    pick = rng.random((n, width)) < 0.05
    rows[pick] = rng.choice(edges, pick.sum())
    if heading is not None:  # math.cos refuses an infinite angle (tested below)
        rows[np.isinf(rows[:, heading]), heading] = np.nan
    return rows


@pytest.mark.parametrize("ports", [MDE, MORE, FLAT], ids=["mde", "more", "flat"])
def test_the_c_rows_are_the_single_envs_and_numpys_bit_for_bit(ports: list[Port]) -> None:
    observer = Observer(ports)
    assert observer._in_c is not None
    heading = next((i for i, p in enumerate(ports) if p.name.startswith("heading")), None)
    raw = _rows(len(ports), heading)
    in_c = observer.of_rows(raw)
    one = np.stack([observer(row) for row in raw])  # the single env's
    plan, observer._in_c = observer._in_c, None
    with np.errstate(invalid="ignore"):  # numpy's own warnings for inf - inf
        in_numpy = observer.of_rows(raw)
    observer._in_c = plan
    assert in_c.shape == one.shape == (len(raw), len(observer.names))
    assert in_c.tobytes() == one.tobytes()
    assert in_c.tobytes() == in_numpy.tobytes()
    assert (np.abs(in_c) <= 1.0).all()
    assert not np.shares_memory(in_c, raw)


def test_angles_and_other_units_stay_in_numpy() -> None:
    angle = Observer([*MDE, Port("bearing", 0.0, "", "rad")])
    other = Observer([*MDE, Port("load", 0.0, "", "%")])
    assert angle._in_c is None
    assert other._in_c is None


def test_an_infinite_heading_is_refused_as_the_single_env_refuses_it() -> None:
    observer = Observer(MDE)
    raw = np.zeros((3, len(MDE)))
    raw[1, 4] = np.inf
    with pytest.raises(ValueError, match="math domain error"):
        observer(raw[1])
    with pytest.raises(ValueError, match="math domain error"):
        observer.of_rows(raw)
