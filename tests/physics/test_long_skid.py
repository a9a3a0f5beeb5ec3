"""A long manoeuvre on low friction converges with the physics rate, over a family of rovers.

On mu 0.1: 4 s straight at full power, 6 s spinning at -100/100 (the rover still sliding
forward), 5 s at 60/100, 5 s at -100/-30. The final pose at 100-800 Hz against 6,400 Hz must
shrink with order >= 0.9 (a least-squares slope over four rates), and the default rover's
pose at 100 Hz must be within 0.8 cm and 0.01 rad. What made it: a wheel that grips beside a
sliding one is solved again with its hub moved by the sliding tyre's force, the scrub is solved
again with the torque the tyres then give (before: order 0.60 in position and 0.54 in heading,
7.5 cm and 0.136 rad at 100 Hz); the pose update is the trapezoid (``bodyio.trapezoid``: 4.8 cm
and 0.066 rad before it, 3.6 cm and 0.059 rad after); the sliding tyres' slip is taken half a
step on (``sliding.mid_step``), the gripping solve is run again with the hubs moved by the
yaw the scrub gives them (``forces.GRIP_PASSES``; 1.6 cm and 0.029 rad) and a sliding tyre's
slip is taken at its rim's mid-step speed (``sliding.slide``): 0.92 cm and 0.021 rad; a
sliding tyre's load is the one its own drive force leaves (``forces.SLIDING_LOAD``; before,
the gripping solve's, whose drive force is the one that would cancel the slip within the
step): 0.66 cm and 0.0112 rad, and a 100 kg rover's plateau (8.9 cm, 0.056 rad) is gone; a
sliding rim that reverses within a step meets its resistance's mean over the step
(``sliding.slide``; before, the end speed's sign for the whole step, and the rim held at zero
within ``R dt / M_w`` of it): 0.61 cm and 0.0062 rad; a step in which a sliding rim passes its
hub's speed is split there (``sliding.slide``): 0.64 cm and 0.0093 rad, the heading's order
1.29 to 1.70 (the 0.0062 had a cancellation at the last change of command), and the 600 N
rover's heading 0.0068 rad at 100 Hz where it was 0.142.

What is left is built while the yaw rate changes with both tyres sliding, where the moment
hardly depends on the yaw rate, so a yaw-rate error made at a change of command or of grip is
never taken back (docs/physics.md).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rig import ON_AXLE, drive

from amsa_phys.physics import bodyio, forces, sliding

RATES = [100, 200, 400, 800]
#: the rovers whose order is held (mass, tyres, geometry); measured position orders 1.15,
#: 1.11, 1.37, 1.19, 1.21, 1.43, heading orders 1.70, 1.95, 0.55, 1.02, 1.39, 1.33 (the stiff
#: rover's heading: 0.0009, 0.0001, 0.00003, 0.0004 rad at 100-800 Hz, below HEADING_FLOOR)
FAMILY = {
    "default": {},
    "light": {"mass": 10.0},
    "stiff": {"slipComplianceLongitudinal": 1e-4, "slipComplianceLateral": 1e-4},
    "soft": {"slipComplianceLongitudinal": 1.0, "slipComplianceLateral": 1.0},
    "on-axle": ON_AXLE,
    "heavy": {"mass": 100.0},
}
#: a heading within this at every rate (a fifth of the default rover's 0.01 rad) has
#: converged: there the errors are signed ~1e-4 rad terms crossing zero between rates, and a
#: slope through them measures where they cross, not an order
HEADING_FLOOR = 0.002
#: a rover held more loosely: the 600 N one converges with order 1.86 in position and is
#: 1.9 cm off at 100 Hz (4.3 cm without the split at the slip's sign change, 0.63 m before the
#: half-step slip); its heading is 0.0068, 0.0143, 0.0065, 0.0034 rad off at 100-800 Hz, first
#: order from 200 Hz but 100 Hz below the line (without the split: 0.142, 0.047, 0.055,
#: 0.00002, a yaw-rate offset made in the first step of the spin, where the left rim falls from
#: 5.8 m/s through its hub's 3.2 m/s; docs/physics.md), so its heading's order is not held.
ROUGH = {
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


def mutant_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, module: Any, name: str, value: Any
) -> float:
    """The default rover's heading error at 100 Hz on the pure step with ``module.name``
    patched to ``value`` (a mutant: the pure step is the one that reads it) against the real
    model's 6,400 Hz run, made before the mutant is patched in: on the pure step (no C
    compiler, or ``AMSA_PHYS_PURE=1``) the reference runs Python too, and patched first it
    would be the mutant's own."""
    ref = pose(tmp_path / "ref", 6400, {})
    monkeypatch.setattr(module, name, value)
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    return abs(float(pose(tmp_path / "100", 100, {})[2] - ref[2]))


@pytest.mark.parametrize("name", list(FAMILY))
def test_a_long_low_friction_manoeuvre_converges_with_order_one(tmp_path: Path, name: str) -> None:
    c = convergence(tmp_path, FAMILY[name])
    assert c["order"] >= 0.9, c
    assert c["heading_order"] >= 0.9 or max(c["heading_errors"]) < HEADING_FLOOR, c
    if name == "default":  # measured 0.64 cm and 0.0093 rad (the target: 0.05 m, 0.01 rad)
        assert c["error"] < 0.008, c
        assert c["heading_error"] < 0.01, c
    if name == "heavy":  # measured 0.29 cm and 0.0032 rad (8.9 cm and 0.056 rad with the
        # gripping solve's load for a sliding tyre: a plateau, orders 0.77 and 0.73)
        assert c["error"] < 0.01, c
        assert c["heading_error"] < 0.01, c


def test_a_strong_rovers_position_converges_and_its_heading_is_within_the_target(
    tmp_path: Path,
) -> None:
    c = convergence(tmp_path, ROUGH["600 N"])
    assert c["order"] >= 0.9, c
    assert c["error"] < 0.05, c  # 100 Hz: measured 1.9 cm (0.63 m with the start's slip)
    # measured 0.0068 rad at 100 Hz, at most 0.0143 at any rate (without the split at the
    # slip's sign change 0.142 and 0.055: the rim passing its hub's speed within a step)
    assert c["heading_error"] < 0.01, c
    assert max(c["heading_errors"]) < 0.02, c


def at_start(body, force, k):  # type: ignore[no-untyped-def]
    """The mutant of ``sliding.mid_step``: the sliding tyres' slip as the step starts."""
    vx, vy, w, angle = body
    return sliding.mid_step((vx, vy, w, angle), (0.0, 0.0, 0.0), (0.0, *k[1:]))


def mutant_slide(end_speed: bool, mean_resistance: bool):  # type: ignore[no-untyped-def]
    """A mutant of ``sliding.slide_once``: the tyre's slip at the rim's end-of-step speed
    (``end_speed``), or the rim's resistance with the end speed's sign for the whole step and
    the rim held at zero whenever its backward Euler step ends within ``R dt / M_w`` of it
    (not ``mean_resistance``)."""

    def slide(u, v, f0, res, ivs, tyre, side, fy_cap, s):  # type: ignore[no-untyped-def]
        kx, ky, ix, iy = tyre
        qy = -ky * side * ivs * iy

        def tyre_x(up: float) -> tuple[float, float]:
            fx = kx * ((up if end_speed else 0.5 * (u + up)) - v) * ivs
            qq = (fx * ix) ** 2 + qy * qy
            scale = 1.0 / math.sqrt(qq) if qq > 1.0 else 1.0
            return fx * scale, scale

        def excess(up: float, fr: float) -> float:
            fm = max(-s.f_max, min(s.f_max, f0 - s.c * up))
            if mean_resistance and up * u < 0.0:
                fr = res * (abs(up) - abs(u)) / (up - u)
            return s.mw * (up - u) - fm + fr + tyre_x(up)[0]

        rest = max(-s.f_max, min(s.f_max, f0)) - tyre_x(0.0)[0]
        need = s.mw * u + rest
        if u > 0.0:
            side_up = 1 if need > res else -1
        elif u < 0.0:
            side_up = -1 if need < -res else 1
        else:
            side_up = 1 if need > res else (-1 if need < -res else 0)
        held = side_up * u <= 0.0 and -res <= rest <= res
        if held if mean_resistance else -res <= need <= res:
            up = 0.0
        else:
            reach = (s.f_max + 1.0 / ix) / s.mw
            if mean_resistance and side_up * u < 0.0:
                reach = reach + res / s.mw
            lo, hi, fr = (0.0, u + reach, res) if need > res else (u - reach, 0.0, -res)
            if mean_resistance:
                lo, hi, fr = (0.0, u + reach, res) if side_up > 0 else (u - reach, 0.0, -res)
            for _ in range(sliding.SLIDE_ITERATIONS):
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                lo, hi = (lo, mid) if excess(mid, fr) > 0.0 else (mid, hi)
            up = 0.5 * (lo + hi)
        fx, scale = tyre_x(up)
        fy = -ky * side * ivs * scale
        return fx, (fy_cap if abs(fy_cap) < abs(fy) else fy), up

    return slide


#: (module, name, mutant, the least heading error it must leave at 100 Hz: each puts it past
#: the 0.01 rad target); measured: slip at the step's start 0.0295 rad, the gripping solve's
#: load 0.36 rad (a heavy rover's plateau was this), one gripping pass 0.0185, the rim's end
#: speed 0.0224, the resistance with the end speed's sign 0.0145, no trapezoid 0.0187
MUTANTS = {
    "slip at the step's start": (forces, "mid_step", at_start, 0.01),
    "the gripping solve's load for a sliding tyre": (forces, "SLIDING_LOAD", False, 0.01),
    "no scrub yaw in the gripping solve": (forces, "GRIP_PASSES", (0,), 0.01),
    "slip at the rim's end-of-step speed": (sliding, "slide_once", mutant_slide(True, True), 0.01),
    "the rim's resistance with its end speed's sign": (
        sliding,
        "slide_once",
        mutant_slide(False, False),
        0.01,
    ),
    "Chipmunk's first-order pose update": (bodyio, "trapezoid", lambda *args: None, 0.01),
}


@pytest.mark.parametrize("mutant", list(MUTANTS))
def test_each_mutant_of_the_step_puts_the_heading_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, mutant: str
) -> None:
    module, name, value, least = MUTANTS[mutant]
    off = mutant_off(tmp_path, monkeypatch, module, name, value)
    assert off > least, off


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
    # measured: position order 1.21 and 0.43 cm, but heading order 0.65 (0.046 rad at 100 Hz)
    assert c["order"] < 0.9 or c["heading_order"] < 0.9 or c["error"] > 0.05, c
