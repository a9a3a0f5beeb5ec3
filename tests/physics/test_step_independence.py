"""A sliding tyre's state does not move with the physics step (issue 31, item 1).

The old model took a saturated tyre's force from the *gripping* solve scaled back onto the
friction ellipse: the forces that would cancel each slip within the step (the longitudinal
one through the 1 kg rim, the lateral one through the 30 kg body), whose ratio depended on
the step and the masses. A steady drift's yaw rate moved by 12 % between 100 and 1,600 Hz
when the issue was filed (the old scheme run as a mutant on today's model: 21 %).
``sliding.slide`` solves the tyre law with the rim instead. These tests hold the steady drift
and the convergence of a skid's pose to the targets of the issue; each has a mutation test
that runs the old scheme (:func:`old_slide`) and shows it fails. A straight spin-up's peak
slip is held to its target too (at the bottom); the old scheme passes that one as well (within
1 %: a pure longitudinal slip has no direction to get wrong), so its mutation test breaks the
sliding tyre's rim solve instead.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rig import ON_AXLE, drive

from amsa_phys.physics import sliding
from amsa_phys.physics.sliding import slide
from amsa_phys.physics.wheel import StepConstants, rim_and_tyre

#: A rover whose motors out-pull its tyres (600 N stall force a wheel, 40 N m current limit):
#: left/right power 60/20 % spins the outer wheel and drags the inner one, a steady drift.
HOT = {"stallForce": 600.0, "freeSpeed": 6.0, "maxWheelTorque": 40.0}


def ground(mu: float) -> dict[str, Any]:
    return {"ground": {"friction": mu, "rolling_resistance": 0.02}}


def old_slide(
    u: float,
    v: float,
    f0: float,
    res: float,
    ivs: float,
    tyre: tuple[float, float, float, float],
    side: float,
    fy_cap: float,
    s: StepConstants,
) -> tuple[float, float, float]:
    """The earlier scheme, as a mutant of ``sliding.slide``: the gripping solve's forces
    scaled onto the ellipse, the rim re-solved with that force held fixed."""
    kx, _ky, ix, iy = tyre
    fx, _ = rim_and_tyre(u, v, f0, res, kx * ivs, s)
    q = (fx * ix) ** 2 + (fy_cap * iy) ** 2
    scale = 1.0 / np.sqrt(q) if q > 1.0 else 1.0
    fx, fy = fx * scale, fy_cap * scale

    def solve(fr: float) -> float:
        up = (s.mw * u + f0 - fr - fx) * s.big_b
        fm = f0 - s.c * up
        if fm > s.f_max or fm < -s.f_max:
            up = u + ((s.f_max if fm > 0 else -s.f_max) - fr - fx) * s.big_bc
        return up

    if u != 0.0:
        up = solve(res if u > 0 else -res)
        if up * u > 0.0:
            return fx, fy, up
    need = max(-s.f_max, min(s.f_max, f0)) + s.mw * u - fx
    if -res <= need <= res:
        return fx, fy, 0.0
    return fx, fy, solve(res if need > 0 else -res)


def mutate(monkeypatch: pytest.MonkeyPatch) -> None:
    """Run the pure Python model (the C step is held equal to it) with the old scheme."""
    monkeypatch.setattr(sliding, "slide", old_slide)
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")


# -- steady drift -------------------------------------------------------------------------------
def drift(tmp_path: Path, rate: int) -> tuple[float, float]:
    """Yaw rate and speed of the drift after 6 s (settled within ~2 s at every rate)."""
    tmp_path.mkdir(exist_ok=True)
    tr, _ = drive(tmp_path, 60, 20, 6, robot=HOT, physics={"rate": rate, **ground(0.8)})
    return float(tr["Rover.yawRate"][-1]), float(tr["Rover.speed"][-1])


def drift_error(tmp_path: Path) -> float:
    """Largest relative difference of yaw rate and speed between 100 Hz and 1,600 Hz."""
    w0, v0 = drift(tmp_path / "a", 100)
    w1, v1 = drift(tmp_path / "b", 1600)
    assert abs(w1) > 2.0, "not a drift"  # the outer wheel spins, the inner one is dragged
    return max(abs(w0 / w1 - 1), abs(v0 / v1 - 1))


def test_a_steady_drift_does_not_depend_on_the_physics_rate(tmp_path: Path) -> None:
    # target 1 %; measured 1.9e-4 in yaw rate and 2.8e-4 in speed (the old scheme on today's
    # model: 21 % and 4.7 %)
    assert drift_error(tmp_path) < 0.01


def test_mutation_drift_check_fails_with_the_old_saturated_scheme(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    mutate(monkeypatch)
    assert drift_error(tmp_path) > 0.01


# -- skid pose convergence ------------------------------------------------------------------------
def skid_pose(tmp_path: Path, rate: int, geometry: dict[str, float] = ON_AXLE) -> np.ndarray:
    """Where a braking, yawing skid (``test_wheels.skid``) leaves the rover 3 s after it began
    (the drive wheels carrying m g / 2 each, as the numbers below were measured, unless
    ``geometry`` says otherwise)."""
    tmp_path.mkdir(exist_ok=True)
    tr, _ = drive(
        tmp_path,
        100,
        100,
        6,
        robot={"stallForce": 1000.0, "freeSpeed": 2.5, "maxWheelTorque": 50.0, **geometry},
        physics={"rate": rate, **ground(0.3)},
        timeline=[
            {"at": 3, "set": {"Ctl.left": -100, "Ctl.right": 100}},
            {"at": 3.3, "set": {"Ctl.left": -100, "Ctl.right": -100}},
        ],
    )
    return np.array([tr["Rover.posX"][-1], tr["Rover.posY"][-1]])


def skid_errors(tmp_path: Path, geometry: dict[str, float] = ON_AXLE) -> list[float]:
    """The pose's distance from the 3,200 Hz run's at 100, 200, 400 and 800 Hz (m)."""
    ref = skid_pose(tmp_path / "ref", 3200, geometry)
    return [float(np.hypot(*(skid_pose(tmp_path / str(r), r, geometry) - ref))) for r in SKID_RATES]


#: the rates of the skid's convergence checks
SKID_RATES = [100, 200, 400, 800]


def within(errs: list[float], bound: float) -> None:
    """Every rate from 100 to 800 Hz within ``bound`` of the 3,200 Hz run. Not a slope: with
    the second-order pose update the 100 Hz error fell from 2.5 to 0.69 cm and every rate now
    sits on a plateau of 0.4-0.7 cm (where the skid's events fall in a step, the same before
    the change), which no four-rate slope describes."""
    assert max(errs) < bound, errs


def test_a_skid_pose_is_rate_independent_to_a_centimetre(tmp_path: Path) -> None:
    # measured against 3,200 Hz: 0.86, 0.60, 0.50, 0.27 cm (0.69 cm at 100 Hz with the sliding
    # slip at the step's start and one gripping solve; with Chipmunk's first-order pose
    # update: 2.5, 1.1, 0.68, 0.55 cm; the old saturated scheme on today's model: 0.66 m, order
    # -0.02: it does not converge)
    within(skid_errors(tmp_path), 0.01)


def test_mutation_skid_check_fails_with_the_old_saturated_scheme(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    mutate(monkeypatch)
    with pytest.raises(AssertionError):
        within(skid_errors(tmp_path), 0.01)


def test_a_skid_pose_is_rate_independent_with_load_transfer(tmp_path: Path) -> None:
    # the default base (caster 30 cm behind, centre of mass 20 cm high): the braking skid moves
    # load onto the drive axle, capped at the traction it allows each step (measured 0.94,
    # 0.47, 0.37, 0.15 cm; 0.62 cm at 100 Hz with the sliding slip at the step's start and
    # one gripping solve; before the trapezoid 2.7 cm; the old scheme: 0.68 m)
    within(skid_errors(tmp_path, {}), 0.01)


# -- spin-up peak slip ----------------------------------------------------------------------------
#: (ground friction, rover) of the spin-ups: the default rover on ice and on snow-like ground
#: (its 40 N current limit against 6-13 N of grip), the 600 N-stall rover on wet ground.
SPIN_UPS = [(0.05, {}), (0.1, {}), (0.3, HOT)]


def peak_slip(tmp_path: Path, rate: int, mu: float, robot: dict[str, Any]) -> float:
    """The largest slip speed, rim minus ground (m/s), of a full-power launch from rest on
    ground ``mu``, sampled at 400 Hz (every step at 100-400 Hz, every eighth at 3,200 Hz: the
    peak is a flat maximum ~0.05-0.09 s in, which that sampling moves by < 3e-5 of itself)."""
    tmp_path.mkdir(exist_ok=True)
    tr, _ = drive(
        tmp_path, 100, 100, 0.5, robot=robot, physics={"rate": rate, **ground(mu)}, rate_hz=400
    )
    slip = np.maximum(tr["Rover.wheelSpeedL"], tr["Rover.wheelSpeedR"]) - tr["Rover.speed"]
    return float(slip.max())


def spin_up_errors(tmp_path: Path) -> list[tuple[float, float]]:
    """(peak slip at 3,200 Hz, relative error of the peak at 100 Hz against it), per spin-up."""
    out = []
    for i, (mu, robot) in enumerate(SPIN_UPS):
        ref = peak_slip(tmp_path / f"ref{i}", 3200, mu, robot)
        out.append((ref, peak_slip(tmp_path / f"run{i}", 100, mu, robot) / ref - 1))
    return out


def test_a_spin_up_peak_slip_does_not_depend_on_the_physics_rate(tmp_path: Path) -> None:
    # target 3 % (issue 31 item 1: -12 % reported, not reproduced on this model); measured
    # +0.08 %, +0.16 % and +0.20 %. The peak is the rim at its plateau less the body's speed,
    # so the rim's fast mode barely enters: backward or forward Euler on the back-EMF moves it
    # by at most -0.9 % and +1.8 % (not caught here; the coast-down tests catch the former).
    runs = spin_up_errors(tmp_path)
    assert min(ref for ref, _ in runs) > 1.0, runs  # 1.3-5.5 m/s of slip: the wheels spin
    assert max(abs(err) for _, err in runs) < 0.03, runs


def rim_not_resolved(
    u: float,
    v: float,
    f0: float,
    res: float,
    ivs: float,
    tyre: tuple[float, float, float, float],
    side: float,
    fy_cap: float,
    s: StepConstants,
) -> tuple[float, float, float]:
    """A mutant of ``sliding.slide``: the tyre's forces of the slide, but the rim's next speed of
    the gripping solve (as if the tyre held): the rim is dragged along with the ground."""
    fx, fy, _ = slide(u, v, f0, res, ivs, tyre, side, fy_cap, s)
    _, up = rim_and_tyre(u, v, f0, res, tyre[0] * ivs, s)
    return fx, fy, up


def test_mutation_spin_up_check_fails_when_the_sliding_rim_is_not_solved(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # measured +254 %, +102 % and +57 % (and a peak slip of 0.6-34 cm/s, not 1.3-5.5 m/s)
    monkeypatch.setattr(sliding, "slide", rim_not_resolved)
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    runs = spin_up_errors(tmp_path)
    assert max(abs(err) for _, err in runs) > 0.03, runs
