"""Context estimators against known contexts: synthetic inputs, then a short run each."""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path

import pytest

import amsa_phys as ap
from amsa_phys.control.estimators.gpsloss import GPSLossMonitor
from amsa_phys.control.estimators.leader import LeaderMonitor
from amsa_phys.control.estimators.motor import MotorMonitor

ROOT = Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "mde_adaptive.yaml"


class _Ctx:
    rng = None
    path = "M"


def _feed(comp, steps, inputs):
    """Step ``comp`` at 4 Hz for ``steps`` steps; ``inputs(t)`` gives each step's inputs."""
    comp.initialize(_Ctx())
    out = {}
    for k in range(steps):
        t = Fraction(k, 4)
        out = comp.do_step(t, inputs(float(t), k)) or out
    return out


@pytest.mark.parametrize("every", [0, 10, 4], ids=["no-loss", "10pct", "25pct"])
def test_gps_loss_rate_counts_held_fixes(every: int) -> None:
    def fixes(t: float, k: int) -> dict[str, float]:
        held = every and k % every == 0
        s = t - 0.25 if held else t  # a held sample repeats the previous fix
        return {"gpsPosX": 0.22 * s, "gpsPosY": 0.0}

    out = _feed(GPSLossMonitor("M", {"window": 30}), 400, fixes)
    # 121 samples in the window; every `every`-th one held: 12 of 121 or 30/31 of 121
    expected = 0.0 if not every else round(121 / every) / 121
    assert out["lossRate"] == pytest.approx(expected, abs=1.5 / 121)


def test_gps_loss_rate_is_zero_before_a_full_window() -> None:
    out = _feed(
        GPSLossMonitor("M", {"window": 30}), 40, lambda t, k: {"gpsPosX": 0.0, "gpsPosY": 0.0}
    )
    assert out["lossRate"] == 0.0


@pytest.mark.parametrize("share", [1.0, 0.6, 0.25])
def test_motor_monitor_recovers_the_delivered_share_in_steady_state(share: float) -> None:
    command = 12.0
    speed = 5.5 * (share * command - 2.9) / 100.0  # the rover model the monitor inverts

    def inputs(t: float, k: int) -> dict[str, float]:
        return {"powerL": command + 3, "powerR": command - 3, "posX": speed * t, "posY": 0.0}

    out = _feed(MotorMonitor("M", {}), 200, inputs)
    assert out["delivered"] == pytest.approx(share, abs=1e-6)


def test_motor_monitor_holds_its_estimate_when_nothing_is_commanded() -> None:
    out = _feed(
        MotorMonitor("M", {}),
        200,
        lambda t, k: {"powerL": 0.0, "powerR": 0.0, "posX": 0.0, "posY": 0.0},
    )
    assert out["delivered"] == 1.0


def test_leader_monitor_straight_track_is_not_turning() -> None:
    out = _feed(LeaderMonitor("M", {}), 200, lambda t, k: {"gpsPosX": 0.22 * t, "gpsPosY": 0.1 * t})
    assert out["turning"] == 0.0
    assert out["turnRate"] == pytest.approx(0.0, abs=1e-9)


def test_leader_monitor_circle_turns_all_the_time_at_its_rate() -> None:
    rate, radius = 0.05, 5.0  # rad/s, m: 0.25 m/s

    def circle(t: float, k: int) -> dict[str, float]:
        return {
            "gpsPosX": radius * math.sin(rate * t),
            "gpsPosY": radius * (1 - math.cos(rate * t)),
        }

    out = _feed(LeaderMonitor("M", {}), 200, circle)
    assert out["turning"] == 1.0
    assert out["turnRate"] == pytest.approx(rate, rel=1e-6)


@pytest.mark.parametrize(
    ("context", "signal", "lo", "hi"),
    [
        ({}, "MotorMonitor.delivered", 0.75, 1.5),
        ({}, "LeaderMonitor.turning", 0.0, 0.08),
        ({}, "LeaderGPSMonitor.lossRate", 0.0, 0.03),
        ({"MyNormalizePower.motorCoef": 50}, "MotorMonitor.delivered", 0.4, 0.6),
        ({"MyNormalizePower.motorCoef": 25}, "MotorMonitor.delivered", 0.18, 0.32),
        ({"LeaderGPS.lostDataGPS": 20}, "LeaderGPSMonitor.lossRate", 0.12, 0.28),
    ],
    # the random leader: tests/adapt/test_estimators_known_contexts.py (where the estimate is
    # sure, over six seeds: a random leader stops for whole windows)
    ids=["nominal-motors", "straight", "no-loss", "worn50", "worn25", "loss20"],
)
def test_estimates_in_a_run_of_each_context(context, signal, lo, hi) -> None:
    """From t = 100 s to 160 s the estimate's mean is on the context's side of the
    thresholds ``amsa-phys adapt`` derives (midway between the mapped levels)."""
    run = ap.run(WORLD_SCENARIO, set={"MyFollowerController.Kv": 0.2, **context})
    t = run.trace["t"]
    values = run.trace[signal][(t >= 100) & (t <= 160)]
    assert lo <= values.mean() <= hi, values.mean()


WORLD_SCENARIO = {
    "world": str(WORLD),
    "duration": 160,
    "seed": 3,
    "trace_columns": ["*Monitor.*"],
}
