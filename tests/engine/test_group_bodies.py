"""The compiled group bodies (``engine/batch_bodies.py``, ``_groupbodies.c``) against the
numpy path of the same ``step_many``: a GPS and a compass group whose members differ in
every parameter the bodies read, stepped side by side, give the same outputs, the same
published rows, the same loss counts and the same state, to the bit; a distance group's
distances are ``math.hypot``'s, and a compass group's deviation is numpy's."""

from __future__ import annotations

import importlib.util
import math
from fractions import Fraction
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine import batch_bodies
from amsa_phys.engine.batch import ParamArrays
from amsa_phys.sensors.compass import Compass
from amsa_phys.sensors.gps import GPS

BUILT = importlib.util.find_spec("amsa_phys.engine._groupbodies") is not None
#: built and not switched off (``AMSA_PHYS_PURE=1``)
needs_c = pytest.mark.skipif(
    not BUILT or batch_bodies.gps_fix() is None,
    reason="the group bodies were not built, or the pure path was asked for",
)


class Ctx:
    def __init__(self, seed: int) -> None:
        self.rng = np.random.default_rng(seed)


#: one member each: quantised or not, losses, bursts, dynamic and turn-on biases (and, for
#: the compass, deviation terms or none)
GPS_MEMBERS: list[dict[str, Any]] = [
    {"stddev": 0.015, "dynamic_bias_stddev": 0.0055, "precision": 0.01, "lostDataGPS": 30},
    {"stddev": 0.5, "burstLoss": 30.0, "burstLength": 4.0, "precision": 0.0},
    # unrounded, so the order of the sums shows in the last bits
    {"stddev": 0.1, "bias_mean": 0.2, "bias_stddev": 0.05, "precision": 0.0, "mean": -0.1},
    {
        "stddev": 0.2,
        "dynamic_bias_stddev": 0.01,
        "dynamic_bias_correlation_time": 3.0,
        "burstLoss": 10.0,
        "burstLength": 2.0,
        "lostDataGPS": 5,
        "precision": 0.001,
    },
]
COMPASS_MEMBERS: list[dict[str, Any]] = [
    {"stddev": 0.01, "lostData": 20.0, "precision": 0.0017, "deviationB": 0.02},
    {  # unrounded, so the order of the sums shows in the last bits
        "stddev": 0.01,
        "mean": 0.05,
        "dynamic_bias_stddev": 0.003,
        "dynamic_bias_correlation_time": 2.0,
        "precision": 0.0,
    },
    {"stddev": 0.0, "precision": 0.0, "mean": 0.3},
    {
        "stddev": 0.02,
        "bias_mean": 0.01,
        "bias_stddev": 0.005,
        "deviationB": 0.02,
        "deviationC": -0.013,
        "deviationD": 0.005,
        "deviationE": 0.0031,
        "precision": 0.0,
    },
]
#: the true readings at each step, per member: ordinary ones, then what a blown-up physics
#: would give (a double that overflows, an infinity, a NaN)
READINGS = [1.0, 2.5, -3.25, 1e9, 3.1, 0.5, 6.0, -7.5] * 3 + [1.7e308, float("inf"), np.nan]


def _group(cls: type, members: list[dict[str, Any]], seed: int) -> list[Any]:
    comps = []
    for k, params in enumerate(members):
        comp = cls(f"S{k}", params)
        comp.initialize(Ctx(seed + k))
        comps.append(comp)
    return comps


def _steps(cls: type, members: list[dict[str, Any]], compiled: bool) -> list[Any]:
    """Every step's (outputs' bytes, published, losses, state) of a group of ``members``."""
    comps = _group(cls, members, 40)
    params, state = ParamArrays(comps), {}
    ports = [p.name for p in cls.inputs]
    n = len(comps)
    seen = []
    with pytest.MonkeyPatch.context() as mp:
        if not compiled:  # the numpy path: no body found
            mp.setattr(batch_bodies, "_body", lambda name: None)
        for k, value in enumerate(READINGS):
            with np.errstate(all="ignore"):
                reading = np.full(n, value) + np.arange(n)  # each member its own reading
                inp = {port: reading * (j + 1) for j, port in enumerate(ports)}
                out, published = cls.step_many(comps, Fraction(k, 4), inp, params, state)
            rows = {port: np.asarray(arr)[published] for port, arr in out.items()}
            kept = {
                key: np.asarray(state[key]).tobytes()
                for key in ("b", "bx", "by", "bad")
                if key in state
            }
            seen.append(
                (
                    {port: arr.tobytes() for port, arr in rows.items()},
                    published.tobytes(),
                    [c.lost for c in comps],
                    kept,
                )
            )
    return seen


@needs_c
@pytest.mark.parametrize(
    ("cls", "members"), [(GPS, GPS_MEMBERS), (Compass, COMPASS_MEMBERS)], ids=["gps", "compass"]
)
def test_the_compiled_body_steps_as_the_numpy_path(
    cls: type, members: list[dict[str, Any]]
) -> None:
    compiled = _steps(cls, members, True)
    numpy_path = _steps(cls, members, False)
    for k, (got, want) in enumerate(zip(compiled, numpy_path, strict=True)):
        assert got == want, f"step {k} (reading {READINGS[k]})"
    # the members lose fixes and publish others: both branches were taken
    losses = [c for _, _, c, _ in compiled]
    assert any(losses[-1])
    assert not all(losses[-1])


@needs_c
def test_the_body_is_what_a_group_after_its_first_step_runs() -> None:
    """The compiled call is used (not the numpy path that the comparison above would also
    pass), and only from the second step: the first sets the biases up in numpy."""
    calls = []
    real = batch_bodies.gps_fix()
    comps = _group(GPS, GPS_MEMBERS, 1)
    state: dict[str, Any] = {}
    with pytest.MonkeyPatch.context() as mp:

        def counted(*args: Any) -> Any:
            calls.append(len(args))
            return real(*args)

        mp.setattr(batch_bodies, "gps_fix", lambda: counted)
        inp = {"posX": np.zeros(4), "posY": np.ones(4)}
        for k in range(3):
            GPS.step_many(comps, Fraction(k), inp, ParamArrays(comps), state)
    assert len(calls) == 2


@needs_c
def test_a_delayed_fix_takes_the_numpy_path() -> None:
    """Latency keeps a history of fixes the body does not hold: the numpy path steps it."""
    members = [{**m, "latency": 0.5} for m in GPS_MEMBERS]
    assert _steps(GPS, members, True) == _steps(GPS, members, False)


@needs_c
def test_a_body_refuses_arrays_of_the_wrong_length() -> None:
    fix = batch_bodies.gps_fix()
    args = [np.zeros(3)] * 20 + [np.zeros(3, bool)] + [np.zeros(3)] * 2 + [np.zeros(3, bool)] * 2
    args[5] = np.zeros(2)
    with pytest.raises(ValueError, match="gy: one float64 per member"):
        fix(*args)


@needs_c
def test_a_distance_group_is_math_hypot_of_each_member() -> None:
    """The DistanceMonitor group's compiled distances are ``math.hypot`` of each member's
    differences (what a run alone computes), on ordinary, huge, tiny, signed-zero, infinite
    and NaN coordinates, and the numpy path's."""
    from amsa_phys.control.monitor import DistanceMonitor

    rng = np.random.default_rng(8)
    edges = [0.0, -0.0, 1e-310, -1e-310, 1.7e308, -1.7e308, np.inf, -np.inf, np.nan, 3.0, 4.0]
    cols = [rng.normal(0, 50, 300) for _ in range(4)]
    for col in cols:
        col[: 3 * len(edges)] = rng.choice(edges, 3 * len(edges))
    inp = dict(zip(("xLeader", "yLeader", "xFollower", "yFollower"), cols, strict=True))
    comps = [object()] * 300
    out, published = DistanceMonitor.step_many(comps, Fraction(0), inp, None, {})
    got = out["distanceFollowerToLeader"]
    assert published is None
    with np.errstate(all="ignore"):
        dx, dy = cols[0] - cols[2], cols[1] - cols[3]
    want = [math.hypot(x, y) for x, y in zip(dx.tolist(), dy.tolist(), strict=True)]
    assert got.tobytes() == np.array(want).tobytes()
    with pytest.MonkeyPatch.context() as mp:  # the numpy path: no body found
        mp.setattr(batch_bodies, "_body", lambda name: None)
        with np.errstate(all="ignore"):
            numpy_path, _ = DistanceMonitor.step_many(comps, Fraction(0), inp, None, {})
    assert numpy_path["distanceFollowerToLeader"].tobytes() == got.tobytes()
    assert np.isinf(got).any()
    assert np.isnan(got).any()


@needs_c
def test_the_compass_deviation_body_is_the_numpy_deviation() -> None:
    """The deviation's products and sums in C equal ``compass.deviation`` on arrays (numpy's
    sines, then its products and sums), on headings of every size and each coefficient
    mix, signed zeros and NaN included."""
    from amsa_phys.sensors.compass import _deviation_many, deviation

    rng = np.random.default_rng(9)
    n = 400
    h = np.concatenate([rng.uniform(-4, 4, n - 6), [0.0, -0.0, 1e6, -1e-300, np.nan, np.pi]])
    coefficients = tuple(rng.choice([0.0, -0.0, 0.02, -0.013, 0.5, 1e-9], n) for _ in range(4))
    got = _deviation_many({}, h, coefficients)
    want = deviation(h, *coefficients)
    assert got.tobytes() == want.tobytes()


def _follower_steps(compiled: bool, steps: int = 120) -> list[bytes]:
    """A FollowerController group stepped ``steps`` times at 10 Hz, every output and the
    speed estimate's state after each step, as bytes: members whose leader fix repeats
    (lost samples), jumps (a glitch), stays unmeasured (distance 0), or whose window holds
    more fixes than the first slots (they double), with feed-forward on and off."""
    from amsa_phys.control.follower import FollowerController

    n = 12
    rng = np.random.default_rng(11)
    settings = [
        {"Kv": 0.2, "Kw": 0.04, "Kff": 0.0, "speedWindow": 3.0},
        {"Kv": 0.35, "Kw": 0.1, "Kff": 1.0, "speedWindow": 3.0},
        {"Kv": 0.1, "Kw": 0.02, "Kff": 0.5, "speedWindow": 4.5},  # > 16 fixes: slots double
        {"Kv": 0.6, "Kw": 0.3, "Kff": 2.0, "speedWindow": 0.25, "maxSpeed": 0.5},
    ]
    comps = [FollowerController(f"F{k}", settings[k % len(settings)]) for k in range(n)]
    p = ParamArrays(comps)
    state: dict[str, Any] = {}
    xl = rng.uniform(-50, 50, n)
    yl = rng.uniform(-50, 50, n)
    seen: list[bytes] = []
    with pytest.MonkeyPatch.context() as mp:
        if not compiled:
            mp.setattr(batch_bodies, "_body", lambda name: None)
        for i in range(steps):
            t = Fraction(i, 10)
            moving = rng.random(n) < 0.8  # the rest repeat their last fix (a lost sample)
            xl = np.where(moving, xl + rng.normal(0.05, 0.02, n), xl)
            yl = np.where(moving, yl + rng.normal(0.03, 0.02, n), yl)
            if i in (40, 41, 90):
                # an impossible jump; 0.4 m where maxSpeed is 0.5 m/s, within a 0.25 s floor's
                # reach of 2 x 0.5 x 0.25 = 0.25 m of it
                k = np.arange(n)
                xl = xl + np.where(k % 4 == 3, 0.4, np.where(k % 3 == 0, 40.0, 0.0))
            xf = xl - rng.uniform(5, 25, n)
            yf = yl + rng.normal(0, 2, n)
            d = np.hypot(xl - xf, yl - yf)
            d[np.arange(n) % 5 == 4] = 0.0 if i < 60 else d[np.arange(n) % 5 == 4]
            inp = {
                "xLeader": xl.copy(),
                "yLeader": yl.copy(),
                "xFollower": xf,
                "yFollower": yf,
                "headingFollower": rng.uniform(-4, 4, n),
                "distanceLeaderFollower": d,
            }
            out, published = FollowerController.step_many(comps, t, inp, p, state)
            assert published is None
            seen.append(b"".join(np.asarray(out[k]).tobytes() for k in sorted(out)))
            seen.append(b"".join(a.tobytes() for a in state["fixes"]) + state["v"].tobytes())
    assert state["fixes"][0].shape[1] > 16  # the long window's slots doubled
    return seen


@needs_c
def test_a_follower_group_is_its_numpy_path_bit_for_bit() -> None:
    """The FollowerController group's compiled step gives the numpy path's powers, speed
    estimates and fix windows, to the bit, step by step: through lost samples, impossible
    jumps, unmeasured distances, feed-forward and a window that outgrows its slots."""
    assert batch_bodies.follower() is not None
    assert _follower_steps(True) == _follower_steps(False)


@needs_c
def test_a_follower_group_is_each_member_stepped_alone() -> None:
    """Each member of a compiled FollowerController group commands what ``do_step`` of a
    copy stepped alone commands (a batched sweep's rows are the runs made alone)."""
    from amsa_phys.control.follower import FollowerController

    n = 6
    rng = np.random.default_rng(12)
    settings = [{"Kff": 0.5 * (k % 3), "Kv": 0.1 + 0.05 * k} for k in range(n)]
    group = [FollowerController(f"G{k}", settings[k]) for k in range(n)]
    alone = [FollowerController(f"A{k}", settings[k]) for k in range(n)]
    for a in alone:
        a.initialize(None)
    p = ParamArrays(group)
    state: dict[str, Any] = {}
    xl = rng.uniform(-20, 20, n)
    for i in range(80):
        t = Fraction(i, 10)
        xl = xl + np.where(rng.random(n) < 0.7, 0.04, 0.0)
        yl = np.full(n, 3.0)
        xf, yf = xl - 15.5, yl + rng.normal(0, 0.5, n)
        inp = {
            "xLeader": xl,
            "yLeader": yl,
            "xFollower": xf,
            "yFollower": yf,
            "headingFollower": rng.uniform(-0.5, 0.5, n),
            "distanceLeaderFollower": np.hypot(xl - xf, yl - yf),
        }
        out, _ = FollowerController.step_many(group, t, inp, p, state)
        for k, a in enumerate(alone):
            want = a.do_step(t, {name: float(col[k]) for name, col in inp.items()})
            for name, value in want.items():
                assert out[name][k] == value or (math.isnan(value) and math.isnan(out[name][k]))
                assert math.copysign(1.0, out[name][k]) == math.copysign(1.0, value)
