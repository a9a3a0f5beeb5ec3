"""The follower's batched step (``step_many``) is its single step (``do_step``) bit for bit.

A batched sweep or vector env steps many controllers at once; each copy must command, and
estimate the leader's speed, exactly as the controller of a run made alone: the trace of a
batched run is byte-identical to the serial one. The leader-speed estimate sums the fixes of
its window; windows of 4, 12 and 40 fixes (the last one beyond the batch's first 16 slots), with
lost fixes and an impossible jump, over copies at different gains.
"""

from __future__ import annotations

from fractions import Fraction
from types import SimpleNamespace

import numpy as np
import pytest

from amsa_phys.control.follower import FollowerController

DEFAULTS = {p.name: p.default for p in FollowerController.params}


@pytest.mark.parametrize("window", [1.0, 3.0, 10.0])
@pytest.mark.parametrize("seed", [1, 2])
def test_step_many_is_do_step_bit_for_bit(window: float, seed: int) -> None:
    n = 24
    rng = np.random.default_rng(seed)
    params = [dict(DEFAULTS, speedWindow=window, Kff=1.0, Kv=0.05 + 0.02 * i) for i in range(n)]
    comps = [FollowerController(f"F{i}", params[i]) for i in range(n)]
    for c in comps:
        c.initialize(None)
    p = SimpleNamespace(**{k: np.array([float(q[k]) for q in params]) for k in DEFAULTS})
    state: dict = {}
    xl, yl = rng.normal(20.0, 3.0, n), rng.normal(0.0, 3.0, n)
    compared = 0
    for k in range(1, 600):  # 60 s at 10 Hz; a new fix every 0.25-ish s, some lost
        t = Fraction(k, 10)
        fresh = (k % 5 in (0, 2, 3)) & (rng.random(n) > 0.2)  # a lost fix repeats the last
        xl = np.where(fresh, xl + rng.normal(0.4, 0.3, n), xl)
        yl = np.where(fresh, yl + rng.normal(0.0, 0.3, n), yl)
        if k == 300:
            xl = xl + 500.0  # an impossible jump: every copy restarts its window
        inp = {
            "xLeader": xl.copy(),
            "yLeader": yl.copy(),
            "distanceLeaderFollower": rng.uniform(5.0, 25.0, n),
            "xFollower": rng.normal(0.0, 1.0, n),
            "yFollower": rng.normal(0.0, 1.0, n),
            "headingFollower": rng.uniform(-3.0, 3.0, n),
        }
        many, _ = FollowerController.step_many(comps, t, inp, p, state)
        for i, c in enumerate(comps):
            one = c.do_step(t, {key: float(v[i]) for key, v in inp.items()})
            for key, value in one.items():
                assert value == many[key][i], (t, i, key)  # == on floats: bit for bit
            compared += 1
    assert compared == 599 * n
    if window == 10.0:  # the batch outgrew its first 16 slots
        assert max(len(c.fixes) for c in comps) > 16
    assert state["v"].min() > 0  # every copy estimated a speed: the sums were exercised
