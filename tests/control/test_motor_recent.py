"""MotorMonitor's ``recent``: the delivered share over a short window, for a rule that must
see motors recover before the 30 s estimate does.

It must be the share the rover model gives (exact in steady state, and through a change of
speed, since the power that went into it is counted), 0 whenever its window cannot judge
(not yet full, or its command cancels out), off (always 0) by default, and leave every other
output exactly as it was.
"""

from __future__ import annotations

import math
from fractions import Fraction

import pytest

from amsa_phys.control.estimators.motor import MotorMonitor

#: the rover model's constants, the template's defaults
MAX_SPEED, FRICTION, TAU = 5.5, 2.9, 10.0


class _Ctx:
    rng = None
    path = "M"


def _rover(share, command, seconds: float):
    """A first-order rover driven at ``command(t)`` % with motors delivering ``share(t)``:
    its position at every 4 Hz step (exact between steps, commands held over each)."""
    x = v = 0.0
    out = []
    for k in range(int(seconds * 4) + 1):
        t = k / 4
        out.append((k, x, command(t)))
        target = (share(t) * command(t) - FRICTION) * MAX_SPEED / 100.0 if command(t) else 0.0
        decay = math.exp(-0.25 / TAU)
        x += target * 0.25 + (v - target) * TAU * (1.0 - decay)
        v = target + (v - target) * decay
    return out


def _drive(share, command, params: dict[str, float], seconds: float):
    comp = MotorMonitor("M", dict(params))
    comp.initialize(_Ctx())
    outs = {}
    for k, x, c in _rover(share, command, seconds):
        inputs = {"powerL": c, "powerR": c, "posX": x, "posY": 0.0}
        outs[k / 4] = dict(comp.do_step(Fraction(k, 4), inputs))
    return outs


@pytest.mark.parametrize("level", [1.0, 0.6, 0.3])
def test_the_recent_share_is_the_delivered_share_in_steady_state(level: float) -> None:
    outs = _drive(lambda t: level, lambda t: 20.0, {"recentWindow": 5.0}, 120.0)
    assert all(o["recent"] == 0.0 for t, o in outs.items() if t < 5.0)  # not yet full
    late = [o["recent"] for t, o in outs.items() if t >= 90.0]
    assert all(v == pytest.approx(level, abs=1e-3) for v in late)


def test_motors_that_recover_show_in_the_recent_share_within_its_window() -> None:
    """Motors at 30 % recover to 80 % at 60 s: the 5 s share reads above 0.6 within 6 s,
    while the 30 s estimate still reads the worn motors (below 0.4)."""
    outs = _drive(lambda t: 0.3 if t < 60 else 0.8, lambda t: 20.0, {"recentWindow": 5.0}, 120)
    assert outs[59.0]["recent"] == pytest.approx(0.3, abs=0.01)
    seen = [t for t, o in outs.items() if 60.0 <= t <= 66.0 and o["recent"] > 0.6]
    assert seen
    assert outs[seen[0]]["delivered"] < 0.4
    assert outs[119.0]["recent"] == pytest.approx(0.8, abs=1e-3)  # settled


def test_a_command_too_small_for_the_short_window_reads_zero() -> None:
    """``minPower`` is the whole window's floor: a window 6 times shorter needs 6 times the
    command (its path speed is 6 times noisier), so 10 % is judged over 15 s, not over 5 s."""
    short = _drive(lambda t: 1.0, lambda t: 10.0, {"recentWindow": 5.0}, 90.0)
    longer = _drive(lambda t: 1.0, lambda t: 10.0, {"recentWindow": 15.0}, 90.0)
    assert all(o["recent"] == 0.0 for o in short.values())
    assert longer[89.0]["recent"] == pytest.approx(1.0, abs=1e-3)


def test_a_window_whose_command_cancels_out_reads_zero() -> None:
    """A loop swinging back and forth: its short windows cannot judge the motors."""

    def command(t: float) -> float:
        return 30.0 if math.sin(2 * math.pi * t / 8.0) >= 0 else -30.0

    outs = _drive(lambda t: 1.0, command, {"recentWindow": 5.0}, 60.0)
    assert all(o["recent"] == 0.0 for t, o in outs.items() if t >= 20.0)


def test_off_by_default_and_the_other_outputs_unchanged() -> None:
    def share(t: float) -> float:
        return 0.3 if t < 50 else 0.9

    def command(t: float) -> float:
        return 20.0 + 15.0 * math.sin(t / 4.0)

    off = _drive(share, command, {}, 100.0)
    on = _drive(share, command, {"recentWindow": 8.0}, 100.0)
    assert all(o["recent"] == 0.0 for o in off.values())
    assert any(o["recent"] > 0.0 for o in on.values())
    keys = ("delivered", "valid", "pathSpeed")
    assert [[o[k] for k in keys] for o in off.values()] == [
        [o[k] for k in keys] for o in on.values()
    ]
