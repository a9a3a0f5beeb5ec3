"""Steady drifts and turns against the documented tyre law, over a family of rovers.

``docs/physics.md`` states the model per wheel: a DC motor behind a current limit, a rim with
Coulomb resistance, a linear-saturating tyre (slip over ``max(|v|, 0.1 m/s)``, the friction
ellipse) and each contact patch's turn-slip moment capped at its own Coulomb torque. A rover
held at constant left/right power settles into a steady circle whose speed, yaw rate,
sideways velocity and rim speeds solve five equations (forward, lateral and yaw balance in
the body frame, each rim's balance). :func:`law` writes them from the page, without the step
code, and :func:`steady_state` solves them by Newton's method; the simulator at the default
100 Hz must settle within 1 % of that state, for light and heavy rovers, stiff and soft
tyres, low and high motor power. The mutation tests run the sliding tyre's lateral force
capped at the gripping solve's share (a heavy drift 4.3 % off), and the scrub capped as one
sum, which left the slow hub's patch twisting past its own cap (the same drift 6.6 % off, at
every physics rate).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rig import ON_AXLE, drive

from amsa_phys.physics import forces, sliding, wheel

G = 9.81
#: the ground of every run
CRR = 0.02
#: (mass kg, tyre compliance c_x = c_y, stall force N, ground friction): light and heavy,
#: near-rigid and default tyres, the default motors (120 N) and motors that out-pull the
#: tyres (600 N). At 600 N and mu 0.8 the outer wheel spins and the inner one is dragged
#: sideways (a drift); at 120 N on mu 0.3 the tyres grip (a steady turn).
FAMILY = [
    (10.0, 1e-4, 600.0, 0.8),
    (10.0, 0.1, 600.0, 0.8),
    (30.0, 1e-4, 600.0, 0.8),
    (30.0, 0.1, 600.0, 0.8),
    (100.0, 1e-4, 600.0, 0.8),
    (100.0, 0.1, 600.0, 0.8),
    (30.0, 1e-4, 120.0, 0.3),
    (100.0, 0.1, 120.0, 0.3),
]
POWER = (60.0, 20.0)


def robot(mass: float, c: float, stall: float) -> dict[str, Any]:
    """The rover's parameters: the axle under the centre of mass (N = m g / 2 a wheel)."""
    fast = stall > 200.0
    return {
        "mass": mass,
        "stallForce": stall,
        "freeSpeed": 6.0 if fast else 1.6,
        "maxWheelTorque": 40.0 if fast else 4.0,
        "slipComplianceLongitudinal": c,
        "slipComplianceLateral": c,
        **ON_AXLE,
    }


def law(p: dict[str, Any], mu: float) -> Callable[[np.ndarray], np.ndarray]:
    """The documented model's steady-state residuals of ``x = (u, v_y, w, u_L, u_R)``: body
    forward and sideways speed, yaw rate, rim speeds. Defaults from ``docs/physics.md``: a
    0.8 x 0.6 m box, track 0.5 m, wheel radius 0.1 m, joint friction 0.2 N m, patch radius
    3 cm, efficiency 100 %."""
    m = p["mass"]
    inertia = m * (0.8**2 + 0.6**2) / 12.0
    h, r = 0.25, 0.1
    n = m * G / 2.0
    res = CRR * m * G / 2.0 + 0.2 / r
    fmax = p["maxWheelTorque"] / r
    cx = p["slipComplianceLongitudinal"]
    cy = p["slipComplianceLateral"]
    torsion, a = 3.0 * math.pi / 16.0, 0.03

    def motor(power: float, u: float) -> float:
        f = p["stallForce"] * (power / 100.0 - u / p["freeSpeed"])
        return max(-fmax, min(fmax, f))

    def tyre(u: float, v: float, vy: float) -> tuple[float, float]:
        s = max(abs(v), 0.1)
        fx, fy = n * (u - v) / s / cx, -n * (vy / s) / cy
        q = math.hypot(fx / (mu * n), fy / (mu * n))
        return (fx / q, fy / q) if q > 1.0 else (fx, fy)

    def residual(x: np.ndarray) -> np.ndarray:
        u, vy, w, ul, ur = x
        vl, vr = u - w * h, u + w * h
        (fxl, fyl), (fxr, fyr) = tyre(ul, vl, vy), tyre(ur, vr, vy)
        cap = torsion * a * mu * n
        scrub = sum(
            max(-cap, min(cap, -torsion * a * a * (n / cx) * w / max(abs(v), 0.1)))
            for v in (vl, vr)
        )
        return np.array(
            [
                -m * w * vy - (fxl + fxr),  # forward: the centripetal share of the drive
                m * w * u - (fyl + fyr),  # sideways: the tyres turn the velocity
                ((fxr - fxl) * h + scrub) / inertia,  # yaw
                motor(POWER[0], ul) - res * np.sign(ul) - fxl,  # rims
                motor(POWER[1], ur) - res * np.sign(ur) - fxr,
            ]
        )

    return residual


def steady_state(f: Callable[[np.ndarray], np.ndarray], x0: list[float]) -> np.ndarray:
    """Newton's method with a finite-difference Jacobian and a backtracking step."""
    x = np.array(x0, dtype=float)
    for _ in range(200):
        fx = f(x)
        if np.abs(fx).max() < 1e-10:
            return x
        jac = np.empty((5, 5))
        for j in range(5):
            d = np.zeros(5)
            d[j] = 1e-7 * max(1.0, abs(x[j]))
            jac[:, j] = (f(x + d) - fx) / d[j]
        step = np.linalg.lstsq(jac, -fx, rcond=None)[0]
        lam = 1.0
        while lam > 1e-6 and np.abs(f(x + lam * step)).max() > np.abs(fx).max():
            lam /= 2.0
        x = x + lam * step
    if np.abs(f(x)).max() < 1e-7:  # converged to rounding (N, m/s)
        return x
    raise AssertionError(f"no steady state: residual {np.abs(f(x)).max():.3g}")


def simulated(
    tmp_path: Path, case: tuple[float, float, float, float], duration: float = 8.0
) -> dict[str, float]:
    """Speed, yaw rate and rim speeds after ``duration`` at 100 Hz (the family settles within
    ~3 s; the drifts on mu 0.3 need ~20 s), and the slowest rim over the last second."""
    mass, c, stall, mu = case
    tmp_path.mkdir(parents=True, exist_ok=True)
    tr, _ = drive(
        tmp_path,
        *POWER,
        duration,
        robot=robot(mass, c, stall),
        physics={"rate": 100, "ground": {"friction": mu, "rolling_resistance": CRR}},
    )
    last = tr["t"] >= duration - 1.0
    rims = np.abs(np.concatenate([tr["Rover.wheelSpeedL"][last], tr["Rover.wheelSpeedR"][last]]))
    # the sideways velocity, which the trace does not log: the central difference of the
    # last three positions, across the heading between them (a steady circle's chord: within
    # ~1e-4 of it at 50 Hz, a start for the law's solve, not a measurement)
    t, x, y, heading = (tr[k][-3:] for k in ("t", "Rover.posX", "Rover.posY", "Rover.heading"))
    vx, vy = (x[2] - x[0]) / (t[2] - t[0]), (y[2] - y[0]) / (t[2] - t[0])
    return {
        "u": float(tr["Rover.speed"][-1]),
        "vy": float(vy * np.cos(heading[1]) - vx * np.sin(heading[1])),
        "w": float(tr["Rover.yawRate"][-1]),
        "ul": float(tr["Rover.wheelSpeedL"][-1]),
        "ur": float(tr["Rover.wheelSpeedR"][-1]),
        "slowest_rim": float(rims.min()),
    }


def law_error(
    tmp_path: Path, case: tuple[float, float, float, float], duration: float = 8.0
) -> tuple[float, dict]:
    """Largest relative difference of speed and yaw rate, simulation against the law."""
    mass, c, stall, mu = case
    sim = simulated(tmp_path, case, duration)
    x = steady_state(
        law(robot(mass, c, stall), mu), [sim["u"], sim["vy"], sim["w"], sim["ul"], sim["ur"]]
    )
    err = max(abs(sim["u"] / x[0] - 1.0), abs(sim["w"] / x[2] - 1.0))
    return err, {"sim": sim, "law": x.tolist()}


@pytest.mark.parametrize("case", FAMILY, ids=lambda c: "m{}-c{}-F{}-mu{}".format(*c))
def test_a_steady_drift_or_turn_matches_the_documented_law_at_100_hz(
    tmp_path: Path, case: tuple[float, float, float, float]
) -> None:
    # target 1 %; measured 0.009-0.020 % for the 600 N drifts but the heavy soft-tyred one
    # (0.39 %: its outer tyre grips, a first-order step error), 0.000-0.025 % for the 120 N
    # turns (0.56-0.89 % before the gripping solve saw the scrub's yaw: forces.GRIP_PASSES)
    err, info = law_error(tmp_path, case)
    assert err < 0.01, info
    # no rim is held at zero (the lateral cap once stuck the inner rim of a stiff drift)
    assert info["sim"]["slowest_rim"] > 0.05, info


TURNS = [case for case in FAMILY if case[2] < 200.0]
#: 600 N drifts on mu 0.3: a slow sideways mode, settled only after ~20 s (at 8 s they were
#: 0.5-4.8 % off, which read as a rate-independent error of the step)
SLOW_DRIFTS = [(10.0, 1e-4, 600.0, 0.3), (30.0, 1e-4, 600.0, 0.3), (100.0, 1e-4, 600.0, 0.3)]


@pytest.mark.parametrize("case", SLOW_DRIFTS, ids=lambda c: "m{}-c{}-F{}-mu{}".format(*c))
def test_a_slowly_settling_drift_on_mu_0_3_matches_the_law(
    tmp_path: Path, case: tuple[float, float, float, float]
) -> None:
    # measured after 20 s: 0.145 %, 0.041 %, 0.004 % (after 8 s: 4.8 %, 1.1 %, 0.47 %)
    err, info = law_error(tmp_path, case, 20.0)
    assert err < 0.01, info
    assert info["sim"]["slowest_rim"] > 0.05, info


def test_the_slow_drift_check_fails_on_a_drift_not_yet_settled(tmp_path: Path) -> None:
    # the same check 12 s earlier, mid-transient: measured 4.8 % (what once read as a step
    # error independent of the rate)
    err, info = law_error(tmp_path, SLOW_DRIFTS[0], 8.0)
    assert err > 0.01, info


@pytest.mark.parametrize("case", TURNS, ids=lambda c: "m{}-c{}-F{}-mu{}".format(*c))
def test_a_gripping_turns_yaw_rate_is_the_laws_at_100_hz(
    tmp_path: Path, case: tuple[float, float, float, float]
) -> None:
    # measured 0.000 % and 0.025 %: the gripping solve is run again with the hubs moved by
    # the yaw the scrub gives them within the step (once: 0.56 % and 0.89 %)
    err, info = law_error(tmp_path, case)
    assert err < 0.001, info


def test_mutation_a_gripping_solve_blind_to_the_scrubs_yaw_misses_a_turns_law(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(forces, "GRIP_PASSES", (0,))
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    err, info = law_error(tmp_path, TURNS[-1])
    assert err > 0.005, info  # measured 0.89 %


def test_the_law_has_a_drift_in_the_family() -> None:
    # the family is not all gentle turns: the stiff-tyred 600 N rover's law state has the
    # outer rim 0.28 m/s ahead of its hub and a sideways slip of 0.6 m/s (both tyres slide)
    x = steady_state(law(robot(30.0, 1e-4, 600.0), 0.8), [1.7, 0.1, -4.3, 3.0, 0.8])
    u, vy, w, ul, _ = x
    assert ul - (u - w * 0.25) > 0.1, x
    assert abs(vy) > 0.3, x


def summed_cap_scrub(
    w: float,
    torque: float,
    kl: float,
    kr: float,
    ksum: float,
    tl: float,
    tr: float,
    ts: float,
    dt_i: float,
) -> float:
    """The mutant: the patches' moments capped as one sum at ``t_l + t_r``."""
    scrub = -ksum * (w + torque * dt_i) / (1.0 + ksum * dt_i)
    return max(-ts, min(ts, scrub))


def test_mutation_a_scrub_capped_as_one_sum_misses_the_law(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # measured: the heavy soft-tyred drift 6.6 % off (the light one 13 %)
    monkeypatch.setattr(forces, "patch_scrub", summed_cap_scrub)
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    err, info = law_error(tmp_path, (100.0, 0.1, 600.0, 0.8))
    assert err > 0.01, info


def shared_cap_slide_pair(
    sat: tuple[bool, bool],
    left: tuple[float, ...],
    right: tuple[float, ...],
    tyre: tuple[float, float, float],
    side: float,
    cancel: float,
    s: wheel.StepConstants,
    mid: tuple[float, float, float, float, float] | None = None,
) -> tuple[float, float, float, float, float, float]:
    """The mutant: each sliding tyre capped at its share of the gripping solve's lateral
    force, a gripping one keeping its share."""
    out = []
    hubs = (
        ((mid[0], mid[1]), (mid[2], mid[3])) if mid else ((left[1], left[4]), (right[1], right[4]))
    )
    side = mid[4] if mid else side
    for slid, (u, _, f0, res, _, ix, iy, fx, fy, up), (v, ivs) in zip(
        sat, (left, right), hubs, strict=True
    ):
        if slid:
            fx, fy, up = sliding.slide(u, v, f0, res, ivs, (tyre[0], tyre[1], ix, iy), side, fy, s)
        out += [fx, fy, up]
    return out[0], out[1], out[2], out[3], out[4], out[5]


def test_mutation_a_sliding_tyre_capped_at_its_gripping_share_misses_the_law(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # measured: the heavy soft-tyred drift 4.3 % off (0.39 % with the real scheme)
    monkeypatch.setattr(forces, "slide_pair", shared_cap_slide_pair)
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    err, info = law_error(tmp_path, (100.0, 0.1, 600.0, 0.8))
    assert err > 0.01, info
