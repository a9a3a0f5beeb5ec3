"""MotorMonitor's ``pathSpeed``: how fast the follower travels, backward counted as forward.

A rule damping a loop that swings on strong motors reads it; it must be the fixes' own path
speed over its window (0 until the window is full), see a swing whatever its mean progress,
follow ``speedWindow`` when one is set, and leave the share and its confidence as they were.
"""

from __future__ import annotations

import math
from fractions import Fraction

import pytest

from amsa_phys.control.estimators.motor import MotorMonitor


class _Ctx:
    rng = None
    path = "M"


def _drive(position, params: dict[str, float] | None = None, seconds: float = 60.0):
    """Step a MotorMonitor at 4 Hz with the rover at ``position(t)`` on the x axis."""
    comp = MotorMonitor("M", dict(params or {}))
    comp.initialize(_Ctx())
    outs = []
    for k in range(int(seconds * 4) + 1):
        t = k / 4
        inputs = {"powerL": 20.0, "powerR": 20.0, "posX": position(t), "posY": 0.0}
        outs.append((t, dict(comp.do_step(Fraction(k, 4), inputs))))
    return outs


def test_a_steady_rover_reads_its_speed_once_the_window_is_full() -> None:
    outs = _drive(lambda t: 0.3 * t)
    early = [o["pathSpeed"] for t, o in outs if t < 29.0]
    late = [o["pathSpeed"] for t, o in outs if t >= 31.0]
    assert early
    assert all(v == 0.0 for v in early)  # not before the window is full
    assert late
    assert all(v == pytest.approx(0.3, rel=1e-9) for v in late)


def test_a_swing_reads_as_fast_whatever_its_mean_progress() -> None:
    """Back and forth about one spot: no progress, yet the path speed is the swing's."""
    amplitude, period = 0.8, 20.0
    outs = _drive(lambda t: amplitude * math.sin(2 * math.pi * t / period), seconds=80.0)
    # the mean path speed of a sine over whole periods: 4 amplitudes per period
    swing = 4 * amplitude / period
    late = [o["pathSpeed"] for t, o in outs if t >= 60.0]
    assert all(v == pytest.approx(swing, rel=0.08) for v in late)


def test_a_short_speed_window_sees_a_change_sooner() -> None:
    def position(t: float) -> float:  # 0.2 m/s, then 0.6 m/s from 40 s
        return 0.2 * t if t < 40 else 8.0 + 0.6 * (t - 40)

    short = dict(_drive(position, {"speedWindow": 10.0}, 70.0))
    whole = dict(_drive(position, {}, 70.0))
    assert short[51.0]["pathSpeed"] == pytest.approx(0.6, rel=1e-9)
    assert whole[51.0]["pathSpeed"] < 0.4  # the 30 s window still mostly holds 0.2 m/s
    assert whole[70.0]["pathSpeed"] == pytest.approx(0.6, rel=1e-9)
    assert short[8.0]["pathSpeed"] == 0.0
    assert short[11.0]["pathSpeed"] == pytest.approx(0.2, rel=1e-9)  # steps from 1 s on


def test_the_share_and_its_confidence_do_not_depend_on_the_speed_window() -> None:
    def position(t: float) -> float:
        return 0.5 * t + 0.3 * math.sin(t / 3)

    a = _drive(position, {}, 90.0)
    b = _drive(position, {"speedWindow": 7.0}, 90.0)
    assert [(o["delivered"], o["valid"]) for _, o in a] == [
        (o["delivered"], o["valid"]) for _, o in b
    ]
    assert any(o["valid"] == 1.0 for _, o in a)
