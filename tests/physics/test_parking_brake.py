"""The holding brake and a parked rover on a slope, against closed forms.

Per drive wheel on a slope θ (default rover, Crr 0.02; the drive wheels hold the whole pull,
the caster rolls): pull P = (m g / 2) sin θ, rim resistance R(θ) = Crr (m g / 2) cos θ +
jointFriction / r, brake force B = brakeTorque / r while the driver applies no voltage.

* parked (0 % power) with a brake it **holds** while P <= R + B, and rolls away above;
* without one, it rolls back at u = (R - P) / c (the shorted motor's back-EMF brakes) until
  the braking reaches the driver's current limit F_max: above P = R + F_max it **runs away**
  (about 0.31 rad for the default rover);
* the brake is released whenever the driver applies voltage: a climb at power is the
  brake-less closed form u = (F0 - R - P) / c.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from rig import drive

from amsa_phys.physics.space import wheel_model
from amsa_phys.physics.templates import rover_params

G = 9.81
CRR = 0.02
#: the current limit's torque: a brake this strong holds the rover on every slope its motors
#: can climb (climbing needs P <= F_max - R, holding P <= R + F_max)
BRAKE = {"brakeTorque": 4.0}
WHEEL = wheel_model(rover_params(**BRAKE), G)


def resistance(angle: float) -> float:
    return WHEEL.resistance(CRR * math.cos(angle))


def pull(angle: float) -> float:
    return WHEEL.half_weight_n * math.sin(angle)


def angle_where(excess: Any) -> float:
    """The slope at which ``excess(θ)`` (rising with θ) crosses zero, by bisection."""
    lo, hi = 0.0, 1.2
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if excess(mid) > 0:
            hi = mid
        else:
            lo = mid
    return lo


def hold_angle() -> float:
    """θ_B: P = R + B."""
    return angle_where(lambda a: pull(a) - resistance(a) - WHEEL.brake_force_n)


def climb_angle() -> float:
    """The steepest slope climbed at 100 %: P = F_max - R."""
    return angle_where(lambda a: pull(a) - (WHEEL.max_force_n - resistance(a)))


def runaway_angle() -> float:
    """Without a brake: P = R + F_max, the shorted motor's braking at the current limit."""
    return angle_where(lambda a: pull(a) - resistance(a) - WHEEL.max_force_n)


def on_slope(
    tmp_path: Path, angle: float, power: float, duration: float, robot: dict[str, Any]
) -> dict[str, np.ndarray]:
    """The rig at ``power`` % on a slope rising towards +x under the whole field."""
    tmp_path.mkdir(parents=True, exist_ok=True)
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
        robot=robot,
        physics={"gravity": G, "ground": {"friction": 0.8, "rolling_resistance": CRR}},
        extra=zone,
    )
    return tr


def moved(tmp_path: Path, angle: float, robot: dict[str, Any]) -> float:
    tr = on_slope(tmp_path, angle, 0.0, 5.0, robot)
    return float(np.abs(tr["Rover.posX"]).max())


def test_the_brake_holds_a_parked_rover_on_every_slope_it_can_climb(tmp_path: Path) -> None:
    assert climb_angle() < hold_angle()  # the closed forms: 0.24 and 0.31 rad
    assert moved(tmp_path / "a", 0.999 * climb_angle(), BRAKE) < 1e-9
    assert moved(tmp_path / "b", 0.98 * hold_angle(), BRAKE) < 1e-9


def test_the_brake_lets_go_above_its_closed_form_angle(tmp_path: Path) -> None:
    assert moved(tmp_path, 1.02 * hold_angle(), BRAKE) > 1e-3


def test_mutation_without_the_brake_the_parked_rover_rolls(tmp_path: Path) -> None:
    assert moved(tmp_path, 0.999 * climb_angle(), {}) > 1e-3


def test_without_a_brake_a_parked_rover_runs_away_above_the_current_limit(
    tmp_path: Path,
) -> None:
    theta = runaway_angle()
    assert 0.3 < theta < 0.32  # the documented ~0.31 rad
    below = on_slope(tmp_path / "below", 0.95 * theta, 0.0, 8.0, {})
    c = WHEEL.back_emf()
    u = (resistance(0.95 * theta) - pull(0.95 * theta)) / c  # rolls back, steadily
    assert abs(float(below["Rover.wheelSpeedL"][-1]) / u - 1) < 1e-4
    above = on_slope(tmp_path / "above", 1.05 * theta, 0.0, 8.0, {})
    speed = np.abs(above["Rover.speed"])
    assert speed[-1] > 3 * abs(u)  # still accelerating: no steady roll-back
    assert speed[-1] > speed[-50] + 0.1


def test_the_brake_is_released_while_the_motors_drive(tmp_path: Path) -> None:
    angle, power = 0.05, 80.0
    tr = on_slope(tmp_path, angle, power, 6.0, BRAKE)
    u = (WHEEL.drive_force(power) - resistance(angle) - pull(angle)) / WHEEL.back_emf()
    assert abs(float(tr["Rover.wheelSpeedL"][-1]) / u - 1) < 1e-6
