"""MotorMonitor's held confidence: a backing-off is not evidence against the last estimate.

A rover at a steady share drives forward for 60 s, then backs off: once for 5 s (a leader
that stops: a third of the window cancels out) or half of every 10 s for good (a loop
oscillating: all of it cancels out). With ``validHold`` the confidence in the held
estimate decays over the hold instead of dropping at once, and ``holdReverse`` ends it at
once when the reversals are an oscillation's.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import pytest

from amsa_phys.control.estimators.motor import MotorMonitor

SHARE = 0.5
COMMAND = 12.0
SPEED = 5.5 * (SHARE * COMMAND - 2.9) / 100.0  # the rover model the monitor inverts


class _Ctx:
    rng = None
    path = "M"


def _run(params: dict[str, Any], oscillate: bool, seconds: float = 120.0) -> list[dict[str, float]]:
    """Outputs at 4 Hz: forward for 60 s, then one back-off or an oscillation."""
    comp = MotorMonitor("M", params)
    comp.initialize(_Ctx())
    x, out = 0.0, []
    for k in range(int(seconds * 4) + 1):
        t = k / 4
        back = t >= 60 and ((t % 10) < 5 if oscillate else t < 65)
        command = -COMMAND if back else COMMAND
        x += (-SPEED if back else SPEED) * 0.25
        out.append(
            dict(
                comp.do_step(
                    Fraction(k, 4), {"powerL": command, "powerR": command, "posX": x, "posY": 0.0}
                )
            )
        )
    return out


def _at(out: list[dict[str, float]], t: float) -> dict[str, float]:
    return out[int(t * 4)]


def test_without_a_hold_backing_off_makes_the_estimate_unsure_at_once() -> None:
    out = _run({}, oscillate=False)
    assert _at(out, 59)["valid"] == 1.0
    assert _at(out, 65)["valid"] == 0.0


def test_the_hold_keeps_the_estimate_trusted_through_a_brief_backing_off() -> None:
    out = _run({"validHold": 80.0, "holdReverse": 0.4}, oscillate=False)
    first = next(k for k, o in enumerate(out) if k / 4 >= 60 and o["valid"] < 1.0)
    last_valid = first - 1
    assert _at(out, 59)["delivered"] == pytest.approx(SHARE, abs=0.02)
    # the confidence falls by 1/80 a second since the last valid window, the estimate held
    for dt in (5.0, 10.0, 15.0):
        o = out[last_valid + int(dt * 4)]
        if o["valid"] == 1.0:
            break  # a valid window again: the hold starts over
        assert o["valid"] == pytest.approx(1.0 - dt / 80.0, abs=1e-9)
        assert o["delivered"] == out[last_valid]["delivered"]
    # the back-off leaves the window: trusted again, never unsure for a moment in between
    assert min(o["valid"] for o in out[4 * 60 :]) > 0.0
    assert _at(out, 110)["valid"] == 1.0


def test_the_confidence_runs_out_when_no_valid_window_comes() -> None:
    out = _run({"validHold": 20.0}, oscillate=True)  # no holdReverse: only the hold ends it
    decaying = [o["valid"] for o in out[4 * 60 :] if 0.0 < o["valid"] < 1.0]
    assert decaying
    assert all(math.isfinite(v) for v in decaying)
    assert _at(out, 100)["valid"] == 0.0
    last = max(k for k, o in enumerate(out) if o["valid"] == 1.0)
    assert _at(out, 100)["delivered"] == out[last]["delivered"]  # held, not re-read


def test_an_oscillation_ends_the_hold_at_once() -> None:
    held = _run({"validHold": 80.0, "holdReverse": 1.0}, oscillate=True)
    cut = _run({"validHold": 80.0, "holdReverse": 0.4}, oscillate=True)
    # the same reversing stretch: held without holdReverse, unsure at once with it
    assert _at(held, 90)["valid"] > 0.0
    assert _at(cut, 90)["valid"] == 0.0
    assert _at(cut, 120)["valid"] == 0.0
