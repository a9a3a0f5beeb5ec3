"""A long manoeuvre on low friction converges with the physics rate, over a family of rovers.

On mu 0.1: 4 s straight at full power, 6 s spinning at -100/100 (the rover still sliding
forward), 5 s at 60/100, 5 s at -100/-30. The final pose at 100-800 Hz against 6,400 Hz must
shrink with order >= 0.9 (a least-squares slope over four rates), and the default rover's
pose at 100 Hz must be within 2 cm and 0.035 rad. What made it: a wheel that grips beside a
sliding one is solved again with its hub moved by the sliding tyre's force, the scrub is solved
again with the torque the tyres then give (before: order 0.60 in position and 0.54 in heading,
7.5 cm and 0.136 rad at 100 Hz); the pose update is the trapezoid (``bodyio.trapezoid``: 4.8 cm
and 0.066 rad before it, 3.6 cm and 0.059 rad after); the sliding tyres' slip is taken half a
step on (``sliding.mid_step``) and the gripping solve is run again with the hubs moved by the
yaw the scrub gives them (``forces.GRIP_PASSES``): 1.6 cm and 0.029 rad.

Not met: 0.01 rad. The rest is built while the yaw rate changes (the spin-up to 6 rad/s and
the two turns after it: the yaw rate ~0.002 rad/s below 6,400 Hz's throughout); the steady
spin itself is now exact (docs/physics.md).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rig import ON_AXLE, drive

from amsa_phys.physics import bodyio, forces, sliding

RATES = [100, 200, 400, 800]
#: the rovers whose order is held (mass, tyres, geometry); measured position orders 1.14,
#: 1.05, 1.00, 1.16, 1.08, heading orders 1.02, 1.07, 0.99, 1.10, 0.96
FAMILY = {
    "default": {},
    "light": {"mass": 10.0},
    "stiff": {"slipComplianceLongitudinal": 1e-4, "slipComplianceLateral": 1e-4},
    "soft": {"slipComplianceLongitudinal": 1.0, "slipComplianceLateral": 1.0},
    "on-axle": ON_AXLE,
}
#: rovers held more loosely. The heavy one (100 kg) gets closer at every rate but not with a
#: clean order (a stick or slip event moving from one step to the next leaves a plateau):
#: 9.6, 6.2, 3.3, 2.0 cm and 0.074, 0.041, 0.022, 0.015 rad at 100-800 Hz (11.5 cm and 0.094
#: rad before the half-step slip). The 600 N one converges with order 0.92 in position and is
#: 3.7 cm off at 100 Hz (0.63 m before the half-step slip), but its heading (0.111, 0.010,
#: 0.003, 0.016 rad) does not converge monotonically: not held.
ROUGH = {
    "heavy": {"mass": 100.0},
    "600 N": {"stallForce": 600.0, "freeSpeed": 6.0, "maxWheelTorque": 40.0},
}


def pose(tmp_path: Path, rate: int, robot: dict[str, Any]) -> np.ndarray:
    tmp_path.mkdir(parents=True, exist_ok=True)
    tr, _ = drive(
        tmp_path,
        100,
        100,
        20,
        robot=robot,
        physics={"rate": rate, "ground": {"friction": 0.1, "rolling_resistance": 0.02}},
        timeline=[
            {"at": 4, "set": {"Ctl.left": -100, "Ctl.right": 100}},
            {"at": 10, "set": {"Ctl.left": 60, "Ctl.right": 100}},
            {"at": 15, "set": {"Ctl.left": -100, "Ctl.right": -30}},
        ],
    )
    return np.array([tr["Rover.posX"][-1], tr["Rover.posY"][-1], tr["Rover.heading"][-1]])


def convergence(tmp_path: Path, robot: dict[str, Any]) -> dict[str, Any]:
    """Orders (position, heading) over 100-800 Hz against 6,400 Hz, the errors at 100 Hz and
    at every rate."""
    ref = pose(tmp_path / "ref", 6400, robot)
    runs = [pose(tmp_path / str(r), r, robot) for r in RATES]
    pos = [float(np.hypot(*(p[:2] - ref[:2]))) for p in runs]
    ang = [abs(float(p[2] - ref[2])) for p in runs]
    x = np.log(1.0 / np.array(RATES))
    return {
        "order": float(np.polyfit(x, np.log(pos), 1)[0]),
        "heading_order": float(np.polyfit(x, np.log(ang), 1)[0]),
        "error": pos[0],
        "heading_error": ang[0],
        "errors": pos,
        "heading_errors": ang,
    }


def mutant_off(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> float:
    """The default rover's heading error at 100 Hz on the pure step (where the mutants are
    patched in) against the compiled step's 6,400 Hz run (the real model)."""
    ref = pose(tmp_path / "ref", 6400, {})
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    return abs(float(pose(tmp_path / "100", 100, {})[2] - ref[2]))


@pytest.mark.parametrize("name", list(FAMILY))
def test_a_long_low_friction_manoeuvre_converges_with_order_one(tmp_path: Path, name: str) -> None:
    c = convergence(tmp_path, FAMILY[name])
    assert c["order"] >= 0.9, c
    assert c["heading_order"] >= 0.9, c
    if name == "default":  # measured 1.63 cm and 0.0293 rad
        assert c["error"] < 0.02, c
        assert c["heading_error"] < 0.035, c


def test_a_heavy_rover_gets_closer_with_the_rate(tmp_path: Path) -> None:
    c = convergence(tmp_path, ROUGH["heavy"])
    assert c["error"] < 0.105, c  # 100 Hz: measured 9.6 cm and 0.074 rad
    assert c["heading_error"] < 0.085, c
    assert c["errors"][-1] < c["errors"][0] / 4, c  # 800 Hz: an order of at least 2/3
    assert c["heading_errors"][-1] < c["heading_errors"][0] / 4, c


def test_a_strong_rovers_position_converges_with_order_one(tmp_path: Path) -> None:
    c = convergence(tmp_path, ROUGH["600 N"])
    assert c["order"] >= 0.9, c
    assert c["error"] < 0.05, c  # 100 Hz: measured 3.7 cm (0.63 m with the start's slip)


def test_mutation_with_the_sliding_slip_at_the_steps_start_the_heading_is_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the sliding tyres' slip as the step starts (no half step): measured 0.0497 rad
    def at_start(body, force, k):  # type: ignore[no-untyped-def]
        vx, vy, w, angle = body
        return sliding.mid_step((vx, vy, w, angle), (0.0, 0.0, 0.0), (0.0, *k[1:]))

    monkeypatch.setattr(forces, "mid_step", at_start)
    off = mutant_off(tmp_path, monkeypatch)
    assert off > 0.035, off


def test_mutation_without_the_scrubs_yaw_in_the_gripping_solve_the_heading_is_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the gripping solve once, its hubs not moved by the scrub: measured 0.0388 rad
    monkeypatch.setattr(forces, "GRIP_PASSES", (0,))
    off = mutant_off(tmp_path, monkeypatch)
    assert off > 0.035, off


def test_mutation_with_chipmunks_first_order_pose_update_the_heading_is_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the body moved by the step's starting velocity (no trapezoid): measured 0.0383 rad
    monkeypatch.setattr(bodyio, "trapezoid", lambda *args: None)
    off = mutant_off(tmp_path, monkeypatch)
    assert off > 0.035, off


@pytest.mark.slow  # the property is the quick tier's (above); this shows its check can fail
def test_mutation_without_solving_the_gripping_wheel_again_it_does_not_converge(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the gripping wheel keeps the joint solve's force and rim speed (unless it slides too)
    real = sliding.slide_pair

    def keep_gripping_force(sat, left, right, tyre, side, cancel, s, mid=None):  # type: ignore[no-untyped-def]
        if sat[0] != sat[1]:  # the mutant: the gripping wheel's force and rim as they were
            out = real(sat, left, right, tyre, side, cancel, s, mid)
            grip = right if sat[0] else left
            i = 3 if sat[0] else 0
            out = list(out)
            out[i], out[i + 2] = grip[7], grip[9]
            return tuple(out)
        return real(sat, left, right, tyre, side, cancel, s, mid)

    monkeypatch.setattr(forces, "slide_pair", keep_gripping_force)
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    c = convergence(tmp_path, {})
    # measured: position order 1.09 and 4.86 cm, but heading order 0.78 (0.103 rad at 100 Hz)
    assert c["order"] < 0.9 or c["heading_order"] < 0.9 or c["error"] > 0.05, c
