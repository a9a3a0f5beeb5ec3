"""SwingMonitor against constructed distance signals and one real run.

A swing supervisor trusts it to say "the loop swings by this much" only on a swing it has
seen turn twice: a growing swing must read its size, period and growth above 1, a damped
one growth below 1, a steady catch-up or fix noise must read nothing (valid 0, amplitude
0), a swing that stopped must leave the window, and a slow straight leader followed on
healthy motors at the robust gain must stay far below any level a rule fires at.
"""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from amsa_phys.control.estimators.swing import SwingMonitor

ROOT = Path(__file__).resolve().parents[2]


class _Ctx:
    rng = None
    path = "S"


def _feed(distance, seconds: float, params: dict[str, float] | None = None):
    """Step a SwingMonitor at 4 Hz on ``distance(t)``; (t, outputs) per step."""
    comp = SwingMonitor("S", dict(params or {}))
    comp.initialize(_Ctx())
    out = []
    for k in range(int(seconds * 4) + 1):
        out.append((k / 4, dict(comp.do_step(Fraction(k, 4), {"distance": distance(k / 4)}))))
    return out


def _swing(amplitude, period: float = 20.0):
    return lambda t: 15.0 + amplitude(t) * math.sin(2 * math.pi * t / period)


def test_a_growing_swing_reads_its_size_period_and_growth() -> None:
    out = _feed(_swing(lambda t: 0.3 * 1.02**t), 120.0)
    _, last = out[-1]
    assert last["valid"] == 1.0
    # the window's largest half swing is the latest: near the envelope at its end
    assert 0.3 * 1.02**100 < last["amplitude"] <= 0.3 * 1.02**120
    assert last["period"] == pytest.approx(20.0, abs=0.3)
    # half a period apart, the envelope grows by 1.02 ** 10
    assert last["growth"] == pytest.approx(1.02**10, rel=0.05)


def test_a_damped_swing_reads_growth_below_one_and_its_first_swing_as_largest() -> None:
    out = _feed(_swing(lambda t: 2.0 * 0.98**t), 90.0)
    _, last = out[-1]
    assert last["valid"] == 1.0
    assert last["growth"] == pytest.approx(0.98**10, rel=0.05)
    # the largest half swing still in the 60 s window: from about 30 s on
    assert 2.0 * 0.98**40 <= last["amplitude"] <= 2.0 * 0.98**25


def test_a_steady_catch_up_is_no_swing() -> None:
    """10 m behind, closing at 0.2 m/s, then holding the reference: never a turning point
    pair, so nothing is valid and the amplitude reads 0 (no false alarm on a catch-up)."""
    out = _feed(lambda t: max(15.0, 25.0 - 0.2 * t), 120.0)
    assert all(o["valid"] == 0.0 and o["amplitude"] == 0.0 for _, o in out)


def test_noise_inside_the_deadband_is_no_swing() -> None:
    rng = np.random.default_rng(3)
    noise = rng.normal(0.0, 0.01, 4 * 120 + 1)  # 1 cm of jitter on a 2 cm wobble
    out = _feed(lambda t: 15.0 + 0.02 * math.sin(t) + noise[round(4 * t)], 120.0)
    assert all(o["valid"] == 0.0 for _, o in out)


def test_a_swing_that_stopped_leaves_the_window() -> None:
    def distance(t: float) -> float:
        return 15.0 + (1.0 * math.sin(2 * math.pi * t / 20) if t < 60 else 0.0)

    out = dict(_feed(distance, 150.0))
    assert out[55.0]["valid"] == 1.0
    assert out[55.0]["amplitude"] == pytest.approx(1.0, abs=0.01)
    # the last turning point is at 55 s (a trough); 60 s of window later nothing is left
    assert out[130.0]["valid"] == 0.0
    assert out[130.0]["amplitude"] == 0.0


def test_a_window_never_mixes_in_a_swing_older_than_it() -> None:
    """A big swing, then a small one: once the big one left the window, the amplitude is the
    small one's (the monitor holds nothing from before its window)."""

    def distance(t: float) -> float:
        a = 2.0 if t < 40 else 0.4
        return 15.0 + a * math.sin(2 * math.pi * t / 20)

    out = dict(_feed(distance, 160.0, {"window": 40.0}))
    assert out[39.0]["amplitude"] > 1.5
    assert out[150.0]["amplitude"] == pytest.approx(0.4, abs=0.02)


@pytest.mark.parametrize("seed", [1, 2])
def test_a_slow_straight_leader_with_healthy_motors_raises_no_alarm(seed: int) -> None:
    """The robust gain behind a straight leader at 0.06 m/s on healthy motors: the loop's
    swings stay below what the robust gain itself makes behind the sweep's nominal leader
    (0.78 m), the least level a derived swing rule could fire at."""
    import amsa_phys as ap

    scenario = {
        "world": str(ROOT / "worlds" / "mde_adaptive_swing.yaml"),
        "duration": 300,
        "seed": seed,
        "trace_columns": ["SwingMonitor.*"],
    }
    run = ap.run(scenario, set={"Leader.cruisePower": 4.0, "MyFollowerController.Kv": 0.2})
    assert float(np.max(run.trace["SwingMonitor.amplitude"])) < 0.4
