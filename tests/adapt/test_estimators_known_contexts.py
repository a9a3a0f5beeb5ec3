"""Context estimators against known contexts they were not derived from: a slow straight
leader, healthy motors under an oscillating follower, a random leader over six seeds, and
the delay with which worn motors are seen."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import amsa_phys as ap

ROOT = Path(__file__).resolve().parents[2]
WORLD = str(ROOT / "worlds" / "mde_adaptive.yaml")


def _run(seed: int, duration: float = 250, timeline=None, **sets):
    scenario = {"world": WORLD, "duration": duration, "seed": seed, "trace_columns": ["*Monitor.*"]}
    if timeline:
        scenario["timeline"] = timeline
    return ap.run(scenario, set={"MyFollowerController.Kv": 0.15, **sets})


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_slow_straight_leader_is_not_turning(seed: int) -> None:
    """At 0.06 m/s the fix noise is most of a segment's course: no turns, and unsure."""
    run = _run(seed, **{"Leader.cruisePower": 4.0})
    after = run.trace["t"] >= 40
    assert run.trace["LeaderMonitor.turning"][after].max() < 0.08  # the straight band
    assert run.trace["LeaderMonitor.valid"][after].max() == 0.0


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_healthy_motors_never_read_above_one(seed: int) -> None:
    """Kv 0.3 makes the follower reverse about its reference; the estimate stays <= 1."""
    run = _run(seed, **{"MyFollowerController.Kv": 0.3})
    delivered = run.trace["MotorMonitor.delivered"]
    assert delivered.max() <= 1.0
    assert delivered.min() >= 0.75  # healthy: never mistaken for worn (0.5) either


def test_a_random_leader_turns_where_its_estimate_is_sure() -> None:
    """Over six seeds, the mean where valid is above the derived straight/random midpoint
    (0.1: the random leader's level is 0.2)."""
    means = []
    for seed in range(1, 7):
        run = _run(seed, duration=300, **{"Leader.behavior": 4})
        t = run.trace["t"]
        sure = (t >= 40) & (run.trace["LeaderMonitor.valid"] > 0.5)
        means.append(float(run.trace["LeaderMonitor.turning"][sure].mean()))
    assert sum(m > 0.1 for m in means) >= 5, means


def test_worn_motors_are_seen_within_twenty_seconds() -> None:
    """motorCoef 100 -> 50 at 150 s: the estimate crosses 0.7 within 20 simulated seconds."""
    for seed in (1, 2, 3):
        run = _run(seed, 260, [{"at": 150, "set": {"MyNormalizePower.motorCoef": 50}}])
        t, d = run.trace["t"], run.trace["MotorMonitor.delivered"]
        seen = t[(t > 150) & (d < 0.7)]
        assert seen.size, seed
        assert seen[0] - 150 <= 20, seed
        assert np.all(d[(t > 150) & (t < 150 + 5)] > 0.7)  # not before the change shows


class _Ctx:
    rng = None
    path = "M"


def _motor(share: float, reverse: int = 0) -> dict:
    """A MotorMonitor fed 60 s of a rover whose speed shows ``share`` of a 20 % command.

    ``reverse`` N: every Nth command is reversed (the rover, with its 10 s speed time
    constant, keeps its speed).
    """
    from fractions import Fraction

    from amsa_phys.control.estimators.motor import MotorMonitor

    comp = MotorMonitor("M", {})
    comp.initialize(_Ctx())
    speed = (share * 20.0 - 2.9) / 100.0 * 5.5
    out: dict = {}
    for k in range(241):
        t = k / 4
        power = -20.0 if reverse and k % reverse == 0 else 20.0
        inputs = {"powerL": power, "powerR": power, "posX": speed * t, "posY": 0.0}
        out = dict(comp.do_step(Fraction(k, 4), inputs) or out)
    return out


def test_a_share_a_little_above_one_is_noise_published_as_one() -> None:
    out = _motor(1.08)
    speed = (1.08 * 20.0 - 2.9) / 100.0 * 5.5  # the path speed is the fixes' own
    assert out == {
        "delivered": 1.0,
        "valid": 1.0,
        "pathSpeed": pytest.approx(speed),
        "recent": 0.0,  # off by default
    }


def test_a_share_far_above_one_or_a_reversing_command_is_invalid() -> None:
    out = _motor(1.5)
    assert (out["delivered"], out["valid"]) == (1.0, 0.0)  # held at its start value
    # two thirds of the command cancel out: worn motors (0.3) would read as healthy (0.9)
    assert _motor(0.3, reverse=3)["valid"] == 0.0
    assert _motor(0.6)["delivered"] == pytest.approx(0.6, abs=0.02)


def test_a_rare_brief_reversal_still_gives_an_estimate() -> None:
    """A high gain on worn motors reverses now and then: the motors are still judged."""
    out = _motor(0.6, reverse=40)  # a twentieth of the command cancels out
    assert out["valid"] == 1.0
    assert out["delivered"] == pytest.approx(0.6, abs=0.05)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_worn_motors_stay_judged_under_their_own_cells_gain(seed: int) -> None:
    """The worn cells' gains reverse the follower now and then; the estimate stays sure.

    Refusing every window with a reversal blinded it under exactly the gain its rule set
    (motors at 29 % under Kv 0.6: 1 % of samples sure), and the fallback undid the switch.
    """
    for coef, kv, low, high in ((29, 0.6, 0.0, 0.35), (50, 0.35, 0.4, 0.7)):
        run = _run(seed, 300, **{"MyNormalizePower.motorCoef": coef, "MyFollowerController.Kv": kv})
        after = run.trace["t"] >= 40
        sure = run.trace["MotorMonitor.valid"][after] > 0.5
        delivered = run.trace["MotorMonitor.delivered"][after][sure]
        assert sure.mean() >= 0.4, (coef, kv)
        # 5-95 % of the sure samples within the cell's band: its rule reads them as worn
        assert low < np.percentile(delivered, 5) <= np.percentile(delivered, 95) < high, (coef, kv)
