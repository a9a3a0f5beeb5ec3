"""A sliding tyre's rim that reverses, or passes its hub's speed, within a step.

The rim's resistance ``R sign(u)`` flips where the rim passes through zero. Taken with the end
speed's sign for the whole step (as it was), a rim reversing under its motor lost up to
``2 R dt`` of momentum at each reversal, and a backward Euler step ending within ``R dt / M_w``
of zero held the rim there even when the motor drove it on: the body kept that as a yaw-rate
offset while both tyres slid on ice (the long manoeuvre's heading, ``test_long_skid.py``).
Likewise the tyre's force flips where the rim passes its hub's speed, and one solve over the
step gave the whole step one side's force (a strong rover's heading did not converge). Here
the rim is checked against the closed form of its own equation,
``M_w du/dt = F_m - R sign(u) - F_x``, with a constant motor force (no back-EMF) and a tyre
sliding at a constant force: two straight pieces, before and after zero (or the hub's speed).
"""

from __future__ import annotations

import pytest

from amsa_phys.physics import sliding
from amsa_phys.physics.sliding import slide
from amsa_phys.physics.wheel import StepConstants

DT = 0.01
RIM = 1.0  # J / r^2 (kg)
RES = 5.0  # the rim's Coulomb resistance (N)
GRIP = 12.0  # the sliding tyre's force (N)
HUB = 10.0  # the hub's speed: the slip keeps its sign, so the tyre's force is constant
CONST = StepConstants(mw=RIM / DT, c=0.0, f_max=1000.0, big_b=0.0, big_bc=0.0, e=0.0, e2=0.0)
#: (N / c_x, N / c_y, 1 / grip_x, 1 / grip_y): a stiff tyre, saturated at GRIP (it pushes the
#: rim forward, the hub running ahead of it)
TYRE = (1e6, 1.0, 1.0 / GRIP, 1.0)


def step(u: float, motor: float) -> float:
    """The rim's speed after one step of :func:`sliding.slide`."""
    return slide(u, HUB, motor, RES, 1.0 / HUB, TYRE, 0.0, 1e9, CONST)[2]


@pytest.mark.parametrize("where", [0.1, 0.3, 0.5, 0.7, 0.9, 0.97])
def test_a_rim_reversing_within_a_step_follows_its_closed_form(where: float) -> None:
    motor = -40.0  # the motor brakes, then drives the rim backward
    net = motor + GRIP  # what the rim feels besides its resistance (N), beyond R: it reverses
    u = -(net - RES) / RIM * where * DT  # it reaches zero at `where` of the step
    exact = (net + RES) / RIM * (1.0 - where) * DT
    # the resistance's sign at the end of the step for all of it is off by up to 2 R dt / M_w
    # (0.1 m/s here; at 0.7 and later it held the rim at zero); the mean over the step's
    # straight path is off by the path's bend at zero only: measured at most 0.0074 m/s
    assert abs(step(u, motor) - exact) < 0.1 * 2.0 * RES * DT / RIM, (u, step(u, motor), exact)


@pytest.mark.parametrize("u", [0.01, 0.05, -0.05])
def test_a_rim_whose_resistance_holds_it_at_rest_stops_within_the_step(u: float) -> None:
    # the motor's pull against the tyre is within the resistance: once stopped, it stays
    motor = -GRIP + (-0.9 * RES if u > 0 else 0.9 * RES)
    assert step(u, motor) == 0.0


def test_a_rim_that_keeps_its_direction_meets_its_resistance_throughout() -> None:
    # braking from 1 m/s without reaching zero: backward Euler with R against the motion
    u = 1.0
    motor = -20.0
    assert step(u, motor) == pytest.approx(u + (motor + GRIP - RES) / RIM * DT, rel=1e-12)


def test_a_rim_passing_its_hubs_speed_within_a_step_gets_each_sides_force_for_its_time() -> None:
    # the motor brakes the rim from 1.3 m/s through its hub's 1.0 m/s: the tyre pushes the
    # ground forward (+GRIP) until then and backward after; the rim stays above zero
    hub, u, motor = 1.0, 1.3, -40.0
    before = (motor - RES - GRIP) / RIM  # the rim's deceleration while it runs ahead
    after = (motor - RES + GRIP) / RIM
    t = (hub - u) / before  # when it passes the hub (0.53 of the step)
    exact_u = hub + after * (DT - t)
    exact_fx = GRIP * (2.0 * t / DT - 1.0)
    fx, _, up = slide(u, hub, motor, RES, 1.0 / hub, TYRE, 0.0, 1e9, CONST)
    # one solve gives the step +GRIP (12 N against 0.63 N); the split, measured, to 1e-9
    assert fx == pytest.approx(exact_fx, abs=1e-6)
    assert up == pytest.approx(exact_u, abs=1e-6)


def test_the_split_solves_each_side_as_one_solve_would() -> None:
    # no crossing: the split changes nothing, bit for bit
    hub, u, motor = 1.0, 2.0, -40.0
    once = sliding.slide_once(u, hub, motor, RES, 1.0 / hub, TYRE, 0.0, 1e9, CONST)
    assert slide(u, hub, motor, RES, 1.0 / hub, TYRE, 0.0, 1e9, CONST) == once
