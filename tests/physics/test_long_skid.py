"""A long manoeuvre on low friction converges with the physics rate, over a family of rovers.

On μ 0.1: 4 s straight at full power, 6 s spinning at -100/100 (the rover still sliding
forward), 5 s at 60/100, 5 s at -100/-30. The final pose at 100-800 Hz against 6,400 Hz must
shrink with order >= 0.9 (a least-squares slope over four rates), and the default rover's
position at 100 Hz must be within 5 cm. Two fixes made it: a wheel that grips beside a sliding
one is solved again with its hub moved by the sliding tyre's force (the gripping solve had
given it the other's force of ~1/dt), and the scrub is solved again with the torque the tyres
then give. Before: order 0.60 in position and 0.54 in heading, 7.5 cm and 0.136 rad at 100 Hz.

The heading is not held within 0.01 rad: pymunk's semi-implicit Euler turns the body by the
step's end yaw rate, a first-order error of α t dt / 2 under a yaw acceleration α (0.032 rad
after a 3 s spin-up from rest at 100 Hz on its own), so 0.066 rad at 100 Hz is the
integrator's; its order is held instead.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rig import ON_AXLE, drive

from amsa_phys.physics import forces, sliding

RATES = [100, 200, 400, 800]
#: the rovers whose convergence is held (mass, tyres, geometry); measured position orders
#: 1.08, 1.02, 1.03, 1.08, 1.06. Not held (reported): a 100 kg rover (order 0.82) and a
#: 600 N-stall one (order 1.08 but 0.64 m at 100 Hz, heading order 0.72).
FAMILY = {
    "default": {},
    "light": {"mass": 10.0},
    "stiff": {"slipComplianceLongitudinal": 1e-4, "slipComplianceLateral": 1e-4},
    "soft": {"slipComplianceLongitudinal": 1.0, "slipComplianceLateral": 1.0},
    "on-axle": ON_AXLE,
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


def convergence(tmp_path: Path, robot: dict[str, Any]) -> dict[str, float]:
    """Orders (position, heading) over 100-800 Hz against 6,400 Hz, and the errors at 100 Hz."""
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
    }


@pytest.mark.parametrize("name", list(FAMILY))
def test_a_long_low_friction_manoeuvre_converges_with_order_one(tmp_path: Path, name: str) -> None:
    c = convergence(tmp_path, FAMILY[name])
    assert c["order"] >= 0.9, c
    assert c["heading_order"] >= 0.9, c
    if name == "default":  # measured 4.84 cm and 0.066 rad
        assert c["error"] < 0.05, c


@pytest.mark.slow  # the property is the quick tier's (above); this shows its check can fail
def test_mutation_without_solving_the_gripping_wheel_again_it_does_not_converge(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the gripping wheel keeps the joint solve's force and rim speed (unless it slides too)
    real = sliding.slide_pair

    def keep_gripping_force(sat, left, right, tyre, side, cancel, s):  # type: ignore[no-untyped-def]
        if sat[0] != sat[1]:  # the mutant: the gripping wheel's force and rim as they were
            out = real(sat, left, right, tyre, side, cancel, s)
            grip = right if sat[0] else left
            i = 3 if sat[0] else 0
            out = list(out)
            out[i], out[i + 2] = grip[7], grip[9]
            return tuple(out)
        return real(sat, left, right, tyre, side, cancel, s)

    monkeypatch.setattr(forces, "slide_pair", keep_gripping_force)
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    c = convergence(tmp_path, {})
    # measured: position order 1.09 and 4.86 cm, but heading order 0.78 (0.103 rad at 100 Hz)
    assert c["order"] < 0.9 or c["heading_order"] < 0.9 or c["error"] > 0.05, c
