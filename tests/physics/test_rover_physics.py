"""The rover's physics against what a user would check by hand.

Tolerances: the wheel model is integrated by pymunk's semi-implicit Euler at 100 Hz, so
steady states match closed forms to well under 1 %; transients are judged more loosely.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from rig import drive, traction_accel

from amsa_phys.physics.space import wheel_model
from amsa_phys.physics.templates import rover_params

# The default rover on the default ground (templates.ROVER_PARAMS, world PHYSICS_DEFAULTS).
P = rover_params()
MASS, G, MU, CRR, TRACK = P.mass, 9.81, 0.8, 0.02, P.track
WHEEL = wheel_model(P, G)
RIM = WHEEL.rim_mass_kg  # a wheel's inertia as a mass at the rim, J / r^2


def test_equal_powers_drive_straight(tmp_path: Path) -> None:
    tr, _ = drive(tmp_path, 50, 50, 60, robot={"heading": 0.7})
    drift = np.degrees(np.abs(tr["Rover.heading"] - 0.7)).max()
    assert drift < 0.1
    # and it moved along its heading: y/x = tan(0.7)
    x, y = tr["Rover.posX"][-1], tr["Rover.posY"][-1]
    assert math.hypot(x, y) > 40
    assert math.degrees(abs(math.atan2(y, x) - 0.7)) < 0.1


def test_opposite_powers_turn_in_place(tmp_path: Path) -> None:
    tr, _ = drive(tmp_path, -40, 40, 20, robot={"x": 3.0, "y": -2.0})
    drift = np.hypot(tr["Rover.posX"] - 3.0, tr["Rover.posY"] + 2.0).max()
    assert drift < 0.05
    # it really turns, and the encoders agree with the yaw rate, w = (uR - uL) / track, up to
    # the tyres' slip against the scrub (0.6 % here; 1.5 % measured, as the scrub moment is
    # applied after the tyres' implicit solve: an O(dt) splitting error in the slip)
    w = (tr["Rover.wheelSpeedR"][-1] - tr["Rover.wheelSpeedL"][-1]) / TRACK
    assert tr["Rover.yawRate"][-1] > 1.0
    assert abs(tr["Rover.yawRate"][-1] - w) / w < 0.02


def test_unequal_powers_settle_on_a_circle_of_constant_radius(tmp_path: Path) -> None:
    tr, _ = drive(tmp_path, 30, 50, 120)
    late = tr["t"] > 30
    x, y = tr["Rover.posX"][late], tr["Rover.posY"][late]
    # centre of the circle: least-squares fit of x^2 + y^2 + D x + E y + F = 0
    a = np.column_stack([x, y, np.ones_like(x)])
    d, e, _f = np.linalg.lstsq(a, -(x * x + y * y), rcond=None)[0]
    cx, cy = -d / 2, -e / 2
    radius = np.hypot(x - cx, y - cy)
    assert radius.std() / radius.mean() < 0.005
    # the kinematic radius from the wheel speeds: (track/2)(vR + vL)/(vR - vL)
    v, w = tr["Rover.speed"][late], tr["Rover.yawRate"][late]
    v_l, v_r = v - w * TRACK / 2, v + w * TRACK / 2
    kinematic = (TRACK / 2) * (v_r + v_l) / (v_r - v_l)
    assert abs(kinematic.mean() - radius.mean()) / radius.mean() < 0.01


def top_speed_error(tmp_path: Path, robot: dict[str, float] | None = None) -> float:
    """Relative gap between the simulated top speed and the default rover's closed form."""
    tr, _ = drive(tmp_path, 100, 100, 30, robot=robot)
    # v_free (1 - (Crr m g / 2 + jointFriction / r) / F_stall) = 1.6 (1 - 4.943 / 120)
    expected = WHEEL.steady_speed(100, CRR)
    assert abs(expected - 1.534) < 1e-3  # the documented default
    return abs(tr["Rover.speed"][-1] - expected) / expected


def test_top_speed_matches_the_motor_and_resistance_closed_form(tmp_path: Path) -> None:
    assert top_speed_error(tmp_path) < 0.005


@pytest.mark.parametrize(
    "robot",
    [{"freeSpeed": 1.55}, {"rollingCoef": 1.5}, {"mass": 40.0}, {"jointFriction": 0.3}],
    ids=["motor", "rolling", "mass", "gearbox"],
)
def test_mutation_top_speed_check_fails_when_a_parameter_is_perturbed(
    tmp_path: Path, robot: dict[str, float]
) -> None:
    assert top_speed_error(tmp_path, robot) > 0.005


def test_lower_motor_coef_gives_lower_top_speed(tmp_path: Path) -> None:
    full, _ = drive(tmp_path, 100, 100, 30, coef=100)
    worn, _ = drive(tmp_path, 100, 100, 30, coef=60)
    v_full, v_worn = full["Rover.speed"][-1], worn["Rover.speed"][-1]
    assert v_worn < v_full
    assert abs(v_worn - WHEEL.steady_speed(60, CRR)) / WHEEL.steady_speed(60, CRR) < 0.005


def test_zero_power_brings_the_rover_to_rest(tmp_path: Path) -> None:
    tr, _ = drive(
        tmp_path, 80, 80, 30, timeline=[{"at": 10, "set": {"Ctl.left": 0, "Ctl.right": 0}}]
    )
    assert tr["Rover.speed"][tr["t"] == 10][0] > 1.0
    assert abs(tr["Rover.speed"][-1]) < 1e-9  # held by static friction, not creeping
    assert tr["Rover.wheelSpeedL"][-1] == tr["Rover.wheelSpeedR"][-1] == 0.0  # rims stuck
    x = tr["Rover.posX"]
    assert abs(x[-1] - x[-50]) < 1e-9


def test_traction_limit_caps_acceleration(tmp_path: Path) -> None:
    # a motor and driver far stronger than the tyres: the wheels spin and the body accelerates
    # at the traction limit, not F / m: the ground pushes it through the drive tyres only, each
    # at most mu N, N the load the statics and the launch's load transfer leave it
    robot = {"stallForce": 2000.0, "maxWheelTorque": 200.0, "freeSpeed": 10.0}
    tr, _ = drive(tmp_path, 100, 100, 1, robot=robot, rate_hz=100)
    t = tr["t"]
    accel = np.diff(tr["Rover.speed"]) / np.diff(t)  # exact: pymunk's semi-implicit Euler
    spinning = (t[1:] > 0.1) & (t[1:] < 0.9)
    limit = traction_accel(MU, robot, G)
    assert limit < 0.8 * MU * G  # a caster-bearing base: well under mu g
    assert np.abs(accel[spinning] - limit).max() < 1e-6 * limit
    # the encoders show the spin: the rims run well ahead of the ground
    assert (tr["Rover.wheelSpeedL"] - tr["Rover.speed"])[t > 0.5].min() > 1.0


def test_acceleration_from_rest_is_the_current_limit_over_mass(tmp_path: Path) -> None:
    # the driver limits the launch to maxWheelTorque / r per wheel; the resistance at the rims
    # and the rims' own inertia (J / r^2 each) are part of what it moves
    tr, _ = drive(tmp_path, 100, 100, 0.4, rate_hz=100)
    t = tr["t"]
    accel = np.diff(tr["Rover.speed"]) / np.diff(t)
    early = (t[1:] > 0.05) & (t[1:] < 0.35)
    expected = 2 * (WHEEL.max_force_n - WHEEL.resistance(CRR)) / (MASS + 2 * RIM)
    assert abs(accel[early].mean() - expected) / expected < 0.01
    assert np.ptp(accel[early]) < 0.02 * expected  # constant: the limit, not the motor curve
