"""The rover's physics against what a user would check by hand.

Tolerances: the wheel model is integrated by pymunk's semi-implicit Euler at 100 Hz, so
steady states match closed forms to well under 1 %; transients are judged more loosely.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from rig import drive

from amsa_phys.physics.wheel import WheelModel

# The default rover on the default ground (templates.ROVER_PARAMS, world PHYSICS_DEFAULTS).
MASS, G, MU, CRR, STALL, FREE, TRACK = 30.0, 9.81, 0.8, 0.02, 45.0, 5.5, 0.5
LOAD = MASS * G / 2
WHEEL = WheelModel(STALL, FREE, 1.0, MU * LOAD, CRR * LOAD)


def test_equal_powers_drive_straight(tmp_path: Path) -> None:
    tr, _ = drive(tmp_path, 50, 50, 60, robot={"heading": 0.7})
    drift = np.degrees(np.abs(tr["Rover.heading"] - 0.7)).max()
    assert drift < 0.1
    # and it moved along its heading: y/x = tan(0.7)
    x, y = tr["Rover.posX"][-1], tr["Rover.posY"][-1]
    assert math.hypot(x, y) > 100
    assert math.degrees(abs(math.atan2(y, x) - 0.7)) < 0.1


def test_opposite_powers_turn_in_place(tmp_path: Path) -> None:
    tr, _ = drive(tmp_path, -40, 40, 20, robot={"x": 3.0, "y": -2.0})
    drift = np.hypot(tr["Rover.posX"] - 3.0, tr["Rover.posY"] + 2.0).max()
    assert drift < 0.05
    # it really turns: wheel speeds ±v give yaw rate 2 v / track
    v = WHEEL.steady_speed(40)  # each wheel, in opposite directions
    assert abs(tr["Rover.yawRate"][-1] - 2 * v / TRACK) / (2 * v / TRACK) < 0.01


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
    expected = WHEEL.steady_speed(100)  # 5.5 * (1 - 2.943 / 45) = 5.14 m/s
    return abs(tr["Rover.speed"][-1] - expected) / expected


def test_top_speed_matches_the_motor_and_resistance_closed_form(tmp_path: Path) -> None:
    assert top_speed_error(tmp_path) < 0.005


@pytest.mark.parametrize(
    "robot",
    [{"freeSpeed": 5.3}, {"rollingCoef": 1.5}, {"mass": 40.0}],
    ids=["motor", "rolling", "mass"],
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
    assert abs(v_worn - WHEEL.steady_speed(60)) / WHEEL.steady_speed(60) < 0.005


def test_zero_power_brings_the_rover_to_rest(tmp_path: Path) -> None:
    tr, _ = drive(
        tmp_path, 80, 80, 30, timeline=[{"at": 10, "set": {"Ctl.left": 0, "Ctl.right": 0}}]
    )
    assert tr["Rover.speed"][tr["t"] == 10][0] > 3.0
    assert abs(tr["Rover.speed"][-1]) < 1e-3
    x = tr["Rover.posX"]
    assert abs(x[-1] - x[-50]) < 1e-3  # not creeping in the last second


def test_a_rover_driven_into_a_wall_stops_and_the_collision_is_counted(tmp_path: Path) -> None:
    walls = {"xmin": -50, "xmax": 20, "ymin": -50, "ymax": 50}
    tr, sim = drive(tmp_path, 60, 60, 30, physics={"walls": walls})
    front = tr["Rover.posX"] + 0.4  # half the chassis length
    assert front.max() < 20.0  # never through the wall
    assert 19.0 < tr["Rover.posX"][-1] < 20.0
    assert abs(tr["Rover.speed"][-1]) < 0.05
    hits = [e for e in sim.events if e.kind == "collision"]
    assert len(hits) >= 1
    assert hits[0].detail == "Rover-wall"


def test_traction_limit_caps_acceleration(tmp_path: Path) -> None:
    # a motor far stronger than the tyres: the wheels slip and a = mu * g, not F / m
    tr, _ = drive(tmp_path, 100, 100, 1, robot={"stallForce": 2000.0})
    early = (tr["t"] > 0.04) & (tr["t"] < 0.3)
    accel = np.gradient(tr["Rover.speed"][early], tr["t"][early]).mean()
    assert abs(accel - MU * G) / (MU * G) < 0.03


def test_acceleration_from_rest_is_force_over_mass(tmp_path: Path) -> None:
    tr, _ = drive(tmp_path, 100, 100, 0.2)
    # at v ~ 0: two wheels at stall force, minus rolling resistance ramping in
    early = (tr["t"] >= 0.02) & (tr["t"] <= 0.06)
    accel = np.gradient(tr["Rover.speed"], tr["t"])[early].mean()
    expected = 2 * STALL / MASS
    assert abs(accel - expected) / expected < 0.1
