"""Slopes (issue 31, item 2): a ``gradeZone`` pulls a rover downhill with ``m g sin(angle)``
and carries ``m g cos(angle)``. Closed forms, default rover on a 0.02 rolling-resistance
ground, per drive wheel (N = m g / 2 its share of the pull and of the base's rolling resistance, the
caster's included; R(θ) = Crr N cos θ + jointFriction / r the rim's
resistance, c = F_stall / v_free the back-EMF, F0 the motor's force at rest):

* it **holds** at rest while N sin θ <= R(θ): the breakaway angle θ* solves N sin θ* = R(θ*);
* above it, motors off (shorted), it **rolls back** at the rim speed u = (R - N sin θ) / c;
* it **climbs** at power p at u = (F0 - R - N sin θ) / c (below the current limit).
Each closed form has a mutation test: a slope the physics ignores fails them.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from rig import drive

from amsa_phys.physics import terrain
from amsa_phys.physics.space import wheel_model
from amsa_phys.physics.templates import rover_params

G = 9.81
CRR = 0.02
WHEEL = wheel_model(rover_params(), G)


def resistance(angle: float) -> float:
    return WHEEL.resistance(CRR * math.cos(angle))


def breakaway_angle() -> float:
    """θ* with (m g / 2) sin θ* = R(θ*), by bisection (the pull rises, the resistance falls):
    the drive wheels carry the whole pull (the caster rolls), each half of it."""
    lo, hi = 0.0, 0.5
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if WHEEL.half_weight_n * math.sin(mid) > resistance(mid):
            hi = mid
        else:
            lo = mid
    return lo


def on_slope(tmp_path: Path, angle: float, power: float, duration: float) -> dict[str, Any]:
    """The rig on a slope rising towards +x under the whole field, at ``power`` %."""
    tmp_path.mkdir(exist_ok=True)
    zone = {
        "Hill": {
            "template": "gradeZone",
            "freq": 1,
            "params": {
                "angle": angle,
                "direction": 0.0,
                "polygon": [[-100, -100], [100, -100], [100, 100], [-100, 100]],
            },
        }
    }
    tr, _ = drive(
        tmp_path,
        power,
        power,
        duration,
        physics={"gravity": G, "ground": {"friction": 0.8, "rolling_resistance": CRR}},
        extra=zone,
    )
    return tr


def displacement(tmp_path: Path, angle: float) -> float:
    tr = on_slope(tmp_path, angle, 0.0, 5.0)
    return float(abs(tr["Rover.posX"]).max())


def test_a_rover_holds_on_a_slope_below_its_breakaway(tmp_path: Path) -> None:
    assert displacement(tmp_path, 0.95 * breakaway_angle()) < 1e-9  # not a micrometre


def test_mutation_hold_check_fails_above_the_breakaway(tmp_path: Path) -> None:
    assert displacement(tmp_path, 1.05 * breakaway_angle()) > 1e-3


def rollback_error(tmp_path: Path) -> float:
    angle = 0.1
    tr = on_slope(tmp_path, angle, 0.0, 6.0)
    u = (resistance(angle) - WHEEL.half_weight_n * math.sin(angle)) / WHEEL.back_emf()
    assert u < -0.1
    return abs(float(tr["Rover.wheelSpeedL"][-1]) / u - 1)


def climb_error(tmp_path: Path) -> float:
    angle, power = 0.05, 80.0
    tr = on_slope(tmp_path, angle, power, 6.0)
    pull = WHEEL.half_weight_n * math.sin(angle)
    u = (WHEEL.drive_force(power) - resistance(angle) - pull) / WHEEL.back_emf()
    assert WHEEL.drive_force(power) - WHEEL.back_emf() * u < WHEEL.max_force_n
    return abs(float(tr["Rover.wheelSpeedL"][-1]) / u - 1)


def test_above_its_breakaway_a_rover_rolls_back_at_the_closed_form_speed(tmp_path: Path) -> None:
    assert rollback_error(tmp_path) < 1e-6


def test_a_rover_climbs_at_the_speed_its_motors_allow(tmp_path: Path) -> None:
    assert climb_error(tmp_path) < 1e-6


@pytest.mark.parametrize("check", [rollback_error, climb_error])
def test_mutation_slope_checks_fail_when_the_physics_ignores_the_slope(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, check: Any
) -> None:
    monkeypatch.setattr(terrain.Terrain, "slope", lambda self, index: (1.0, 0.0, 0.0))
    with pytest.raises(AssertionError):
        assert check(tmp_path) < 1e-3


def test_the_compiled_and_the_pure_step_agree_on_a_slope(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Bit for bit, on a slope rising across the rover's way (the lateral grip carries
    gravity; driving, the wheels too), parked, then driving off and turning, then coasting
    to a stop; parked across the slope, the rover is held sideways by its tyres."""
    runs = []
    for pure in ("0", "1"):
        monkeypatch.setenv("AMSA_PHYS_PURE", pure)
        tmp = tmp_path / pure
        tmp.mkdir()
        zone = {
            "Hill": {
                "template": "gradeZone",
                "freq": 1,
                "params": {
                    "angle": 0.15,
                    "direction": math.pi / 2,  # uphill to the rover's left
                    "polygon": [[-100, -100], [100, -100], [100, 100], [-100, 100]],
                },
            }
        }
        tr, _ = drive(
            tmp,
            0,
            0,
            8,
            extra=zone,
            timeline=[
                {"at": 2, "set": {"Ctl.left": 70, "Ctl.right": 40}},
                {"at": 5, "set": {"Ctl.left": 0, "Ctl.right": 0}},
            ],
        )
        runs.append(tr)
    for name in runs[0]:
        assert (runs[0][name] == runs[1][name]).all(), name
    assert abs(runs[0]["Rover.posX"][runs[0]["t"] <= 2]).max() < 1e-9  # parked across: held
