"""MotorMonitor over forward seconds only: a leader's stop is not evidence about the motors.

A rover on the monitor's own first-order model (speed time constant 10 s, friction 2.9 %,
5.5 m/s per 100 %) drives on worn motors; its follower command now and then backs off (a
leader that stops), idles (a follower waiting at its distance) or swings between full
forward and full reverse (an oscillating loop). With ``forwardPower`` the monitor estimates
the share from the seconds whose command has been forward for ``settle`` s: the back-off
neither moves the estimate nor makes it unsure, a quiet wait keeps it, the oscillation
makes it unsure, and a command beyond the actuator's limit counts as the limit.
"""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction
from typing import Any

from amsa_phys.control.estimators.motor import MotorMonitor

SHARE = 0.5
FORWARD = {"forwardPower": 3.0, "settle": 5.0, "quietPower": 15.0}


class _Ctx:
    rng = None
    path = "M"


def _run(params: dict[str, Any], command: Callable[[float], float], seconds: float = 150.0):
    """Outputs at 4 Hz of a rover whose motors deliver SHARE of ``command(t)`` (clamped)."""
    comp = MotorMonitor("M", params)
    comp.initialize(_Ctx())
    x = v = 0.0
    out = []
    for k in range(int(seconds * 4) + 1):
        t = k / 4
        c = command(t)
        out.append(
            dict(comp.do_step(Fraction(k, 4), {"powerL": c, "powerR": c, "posX": x, "posY": 0.0}))
        )
        delivered = SHARE * max(-100.0, min(100.0, c))
        for _ in range(25):  # the rover's first-order speed over the next 0.25 s
            if delivered > 2.9:
                target = 5.5 * (delivered - 2.9) / 100
            elif delivered < -2.9:
                target = 5.5 * (delivered + 2.9) / 100
            else:
                target = 0.0
            v += (target - v) * 0.01 / 10.0
            x += v * 0.01
    return out


def _at(out: list[dict[str, float]], t: float) -> dict[str, float]:
    return out[int(t * 4)]


def _stop(t: float) -> float:
    """Forward at 12 %, backing off at -12 % for 6 s at 60 s (a leader that stops)."""
    return -12.0 if 60 <= t < 66 else 12.0


def test_a_leader_stop_neither_moves_the_estimate_nor_makes_it_unsure() -> None:
    out = _run(FORWARD, _stop)
    for t in range(50, 151, 5):
        assert _at(out, t)["valid"] == 1.0, t
        assert abs(_at(out, t)["delivered"] - SHARE) < 0.03, t


def test_without_forward_seconds_the_same_stop_makes_it_unsure() -> None:
    out = _run({}, _stop)  # the whole window's mean: a third of it cancels out
    assert _at(out, 59)["valid"] == 1.0
    assert _at(out, 70)["valid"] == 0.0


def test_a_quiet_wait_keeps_the_estimate_and_a_loud_oscillation_does_not() -> None:
    def wait(t: float) -> float:
        return 12.0 if t < 60 else (2.0 if int(t) % 2 else -2.0)

    def swing(t: float) -> float:
        return 12.0 if t < 60 else (150.0 if int(t) % 12 < 6 else -150.0)

    quiet = _run(FORWARD, wait)
    loud = _run(FORWARD, swing)
    assert _at(quiet, 140)["valid"] == 1.0
    assert abs(_at(quiet, 140)["delivered"] - SHARE) < 0.03
    assert all(_at(loud, t)["valid"] == 0.0 for t in range(110, 151))


def test_a_command_beyond_the_actuators_limit_counts_as_the_limit() -> None:
    out = _run({**FORWARD, "maxShare": 10.0}, lambda t: 150.0)
    assert abs(_at(out, 140)["delivered"] - SHARE) < 0.03
    unclamped = _run({**FORWARD, "maxShare": 10.0, "powerMax": 1000.0}, lambda t: 150.0)
    assert _at(unclamped, 140)["delivered"] < 0.4  # 150 % read as commanded: a third short


def test_whole_window_judges_a_window_with_too_few_forward_seconds() -> None:
    """A high gain on worn motors reverses briefly and often: every reversal costs the
    settling time, too few seconds count, but little of the command cancels out."""

    def flicker(t: float) -> float:
        return -4.0 if t >= 60 and int(t) % 7 == 0 else 20.0

    alone = _run(FORWARD, flicker)
    whole = _run({**FORWARD, "wholeWindow": 1.0}, flicker)
    assert _at(alone, 140)["valid"] == 0.0
    assert _at(whole, 140)["valid"] == 1.0
    assert abs(_at(whole, 140)["delivered"] - SHARE) < 0.05
