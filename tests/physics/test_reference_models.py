"""The simulation against independent references: unicycle kinematics, coast-down law,
energy, convergence in the physics rate, invariance under rigid motions of the world.

Each check is a function returning the measured discrepancy, so the mutation tests at the
bottom can show that the same check fails when one physical parameter is perturbed.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from rig import drive

from amsa_phys.physics import wheel
from amsa_phys.physics.space import wheel_model
from amsa_phys.physics.templates import rover_params

P = rover_params()
MASS, G, CRR, TRACK = P.mass, 9.81, 0.02, P.track
WHEEL = wheel_model(P, G)
#: Tyres made nearly rigid (slip compliances 1e-4: 0.01 % slip at full grip) and no scrub,
#: so the rover is the ideal unicycle: the only error is the trapezoidal integration at 100 Hz
#: and the lateral slip the grip needs one step to cancel; 0.5 % of the distance covers both.
#: (With the default tyres the encoders drift from the truth by their slip: wheel odometry.)
RIGID_TYRES = {"slipComplianceLongitudinal": 1e-4, "slipComplianceLateral": 1e-4, "patchRadius": 0}
UNICYCLE_TOLERANCE = 0.005
COAST_TOLERANCE = 0.01


def unicycle_error(tmp_path: Path, physical_track: float = TRACK) -> float:
    """Integrate the ideal unicycle (track ``TRACK``) with the wheel speeds the rover reports;
    return the final position error relative to the distance travelled."""
    robot = {"track": physical_track, **RIGID_TYRES}
    tr, _ = drive(tmp_path, 35, 60, 30, rate_hz=100, robot=robot)
    v_l, v_r = tr["Rover.wheelSpeedL"], tr["Rover.wheelSpeedR"]  # encoder readings
    v_m, w_m = (v_l + v_r) / 2, (v_r - v_l) / TRACK
    dt = np.diff(tr["t"])
    theta = np.concatenate([[0.0], np.cumsum((w_m[1:] + w_m[:-1]) / 2 * dt)])
    x = np.concatenate(
        [[0.0], np.cumsum((v_m[1:] * np.cos(theta[1:]) + v_m[:-1] * np.cos(theta[:-1])) / 2 * dt)]
    )
    y = np.concatenate(
        [[0.0], np.cumsum((v_m[1:] * np.sin(theta[1:]) + v_m[:-1] * np.sin(theta[:-1])) / 2 * dt)]
    )
    travelled = np.sum(np.abs(v_m[1:]) * dt)
    err = math.hypot(x[-1] - tr["Rover.posX"][-1], y[-1] - tr["Rover.posY"][-1])
    return err / travelled


def test_unicycle_model_reproduces_the_trajectory(tmp_path: Path) -> None:
    assert unicycle_error(tmp_path) < UNICYCLE_TOLERANCE


def coast_down_error(tmp_path: Path, stall_force: float = P.stallForce) -> float:
    """Largest relative gap between the simulated coast-down and the closed form."""
    return coast_down(tmp_path, stall_force)[0]


def coast_down(tmp_path: Path, stall_force: float = P.stallForce) -> tuple[float, float]:
    """(largest relative gap between the simulated coast-down's speed and the closed form,
    relative error of its stop time: the first physics step at rest against the closed
    form's stop; at 100 Hz the step grid alone makes that up to +1.6 % here)."""
    tr, _ = drive(
        tmp_path,
        80,
        80,
        20,
        # a current limit that never binds: the shorted motor brakes on its own curve; rigid
        # tyres, so the rims turn with the ground (a compliant tyre slips ~2 % while braking
        # here, which lowers the back-EMF's braking by as much: test_wheels checks slip)
        robot={"stallForce": stall_force, "maxWheelTorque": 100.0, **RIGID_TYRES},
        timeline=[{"at": 10, "set": {"Ctl.left": 0, "Ctl.right": 0}}],
    )
    # (m + 2 J/r^2) v' = -2 F_stall v / v_free - 2 R  (shorted motor brakes, resistance at
    # the rims: rolling and gearbox friction; the rims' inertia slows down with the body)
    inertia = MASS + 2 * WHEEL.rim_mass_kg
    k = 2 * WHEEL.back_emf() / inertia
    c = 2 * WHEEL.resistance(CRR) / inertia
    t0 = 10.0
    v0 = tr["Rover.speed"][tr["t"] == t0][0]
    t_stop = math.log(1 + k * v0 / c) / k
    sel = (tr["t"] > t0) & (tr["t"] < t0 + 0.8 * t_stop)  # above the v_eps smoothing
    t = tr["t"][sel] - t0
    model = (v0 + c / k) * np.exp(-k * t) - c / k
    gap = float(np.max(np.abs(tr["Rover.speed"][sel] - model) / v0))
    after = tr["t"] - t0
    stop = float(after[np.argmax((after > 0) & (tr["Rover.speed"] <= 1e-6))])
    return gap, stop / t_stop - 1


def test_coast_down_follows_the_braking_and_rolling_law(tmp_path: Path) -> None:
    assert coast_down_error(tmp_path) < COAST_TOLERANCE


def test_coast_down_decays_and_stops_as_the_closed_form(tmp_path: Path) -> None:
    # issue 31 item 1: the back-EMF split between the step's start and end
    # (wheel.emf_implicitness) decays the 0.21 s motor time constant at the exact rate at
    # 100 Hz: measured 1.8e-5 of the initial speed off the exponential, the stop +1.1 % (the
    # first step after the closed form's 0.633 s). Backward Euler: 0.9 % and +4.3 %.
    gap, stop = coast_down(tmp_path)
    assert gap < 2e-4
    assert abs(stop) < 0.02


def test_mutation_coast_down_timing_fails_with_backward_euler_on_the_motor(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(wheel, "emf_implicitness", lambda *a: 1.0)
    gap, stop = coast_down(tmp_path)
    assert gap > 2e-4
    assert abs(stop) > 0.02


#: Coast-downs with the default, compliant tyres (no closed form: the tyres slip while the
#: motors brake): the default rover (current-limited braking), a current limit that never
#: binds, a strong and a weak motor.
COASTS = [{}, {"maxWheelTorque": 100.0}, {"stallForce": 200.0}, {"stallForce": 60.0}]


def coast_stop(tmp_path: Path, rate: int, robot: dict[str, float]) -> float:
    """When a coast-down from 80 % power falls through 1 mm/s (s after the motors go to 0),
    logged at every physics step and interpolated between steps, so that the step grid's
    1.4 % at 100 Hz does not hide what the integration does."""
    tmp_path.mkdir(exist_ok=True)
    tr, _ = drive(
        tmp_path,
        80,
        80,
        3,
        robot=robot,
        physics={"rate": rate},
        timeline=[{"at": 2, "set": {"Ctl.left": 0, "Ctl.right": 0}}],
        rate_hz=rate,
    )
    sel = tr["t"] >= 2
    t, v = tr["t"][sel] - 2, tr["Rover.speed"][sel]
    i = int(np.argmax(v <= 1e-3))
    assert v[0] > 1.0  # a coast-down from speed
    assert i > 0  # that stops within the run
    return float(t[i - 1] + (v[i - 1] - 1e-3) / (v[i - 1] - v[i]) * (t[i] - t[i - 1]))


def coast_stop_errors(tmp_path: Path) -> list[float]:
    """Relative error of the stop time at 100 Hz against 3,200 Hz, per rover of COASTS."""
    return [
        coast_stop(tmp_path / f"run{i}", 100, robot) / coast_stop(tmp_path / f"ref{i}", 3200, robot)
        - 1
        for i, robot in enumerate(COASTS)
    ]


def test_coast_down_stop_time_does_not_depend_on_the_physics_rate(tmp_path: Path) -> None:
    # issue 31 item 1's target: within 2 % of a fine-step reference (it was +6 %); measured
    # +0.28 %, +0.45 %, +0.31 % and +0.28 % (backward Euler on the motor: +1.3 % to +2.4 %).
    # Not "at rest": once the rims stick, the slip-rate tyre's last ~0.3 mm/s decays in a
    # ~1 ms mode that backward Euler at 100 Hz ends in 3 steps, so the first step at exactly
    # zero speed is +1.8 % to +3.2 % late at 100 Hz (the rims stop within 0.7 %).
    errs = coast_stop_errors(tmp_path)
    assert max(abs(e) for e in errs) < 0.02, errs


def test_mutation_coast_down_stop_check_fails_with_backward_euler_on_the_motor(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(wheel, "emf_implicitness", lambda *a: 1.0)
    errs = coast_stop_errors(tmp_path)
    assert max(abs(e) for e in errs) > 0.02, errs


def test_no_energy_gain_while_coasting(tmp_path: Path) -> None:
    tr, _ = drive(
        tmp_path, 30, 90, 20, timeline=[{"at": 8, "set": {"Ctl.left": 0, "Ctl.right": 0}}]
    )
    inertia = MASS * (0.8**2 + 0.6**2) / 12
    rims = tr["Rover.wheelSpeedL"] ** 2 + tr["Rover.wheelSpeedR"] ** 2
    energy = (
        0.5 * MASS * tr["Rover.speed"] ** 2
        + 0.5 * inertia * tr["Rover.yawRate"] ** 2
        + 0.5 * WHEEL.rim_mass_kg * rims
    )
    coasting = energy[tr["t"] >= 8]
    assert np.all(np.diff(coasting) <= 1e-12)
    assert coasting[-1] < 1e-6


def final_state(tmp_path: Path, rate: int) -> np.ndarray:
    tr, _ = drive(
        tmp_path,
        70,
        70,
        20,
        physics={"rate": rate},
        timeline=[{"at": 8, "set": {"Ctl.left": 20, "Ctl.right": 55}}],
    )
    return np.array([tr["Rover.posX"][-1], tr["Rover.posY"][-1], tr["Rover.speed"][-1]])


def test_results_converge_as_the_physics_rate_rises(tmp_path: Path) -> None:
    s100, s200, s400 = (final_state(tmp_path, r) for r in (100, 200, 400))
    d1 = np.linalg.norm(s100[:2] - s400[:2])
    d2 = np.linalg.norm(s200[:2] - s400[:2])
    # ~8 m of straight driving then 12 s on a tight circle (radius ~0.5 m, ~6 m of path):
    # first-order integration, so 100 Hz lands within 0.5 % of the path of 400 Hz, and
    # halving dt at least roughly halves the gap
    assert d1 < 0.005 * 14
    assert d2 < 0.6 * d1
    # the turn does no work on the rover: its speed does not depend on the rate
    assert abs(s100[2] - s400[2]) / s400[2] < 1e-4


def test_invariance_under_rotating_and_translating_the_world(tmp_path: Path) -> None:
    base, _ = drive(tmp_path, 40, 70, 15)
    phi, dx, dy = 1.1, 120.0, -75.0
    moved, _ = drive(tmp_path, 40, 70, 15, robot={"x": dx, "y": dy, "heading": phi})
    c, s = math.cos(phi), math.sin(phi)
    x = dx + c * base["Rover.posX"] - s * base["Rover.posY"]
    y = dy + s * base["Rover.posX"] + c * base["Rover.posY"]
    assert np.max(np.hypot(x - moved["Rover.posX"], y - moved["Rover.posY"])) < 1e-6
    assert np.max(np.abs(moved["Rover.speed"] - base["Rover.speed"])) < 1e-9


# -- mutation checks: the same checks fail when the physics is wrong ------------------------
@pytest.mark.parametrize("track", [0.45, 0.55], ids=["track-10pc", "track+10pc"])
def test_mutation_kinematics_check_fails_when_the_rover_track_is_perturbed(
    tmp_path: Path, track: float
) -> None:
    assert unicycle_error(tmp_path, physical_track=track) > UNICYCLE_TOLERANCE


def test_mutation_coast_down_check_fails_with_a_wrong_motor(tmp_path: Path) -> None:
    assert coast_down_error(tmp_path, stall_force=P.stallForce * 0.9) > COAST_TOLERANCE
