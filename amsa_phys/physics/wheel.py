"""One driven wheel: motor and driver, spinning rim, tyre. Pure math, no pymunk.

This module is the readable statement of the wheel model and its closed forms;
``forces.rover_step`` (the pure path's one copy, which ``_step.c`` mirrors) inlines the same
arithmetic and is tested against :func:`rim_and_tyre`, :func:`wheel_pair` and
``sliding.slide``.

Forces are expressed at the ground (N), speeds at the rim (m/s): the wheel's spin state is its
rim speed ``u = omega * r`` (what an encoder measures), and its inertia acts as a mass
``J / r**2`` at the rim. Per wheel, with ``v`` the ground speed of the wheel's hub along the
heading and ``N`` the normal load:

* **Driver and motor** (a voltage-controlled DC motor through a gearbox): power ``p`` (%)
  inside the driver's deadband gives no voltage; otherwise
  ``F_m = F_stall * (eta * p/100 - u / v_free)``, clamped to ``+-F_max`` — the driver's
  current limit (``maxWheelTorque / r``). Back-EMF makes the force fall with rim speed; the
  limit bounds both the launch and regenerative braking (reversing at speed asks for twice the
  stall force; the driver delivers ``F_max``).
* **Resistance at the rim**: ``R = Crr * N + jointFriction / r`` (rolling resistance and the
  gearbox's Coulomb friction), against the rim's motion, and *static* at rest: a wheel at rest
  stays at rest while the net force on it is below ``R``. That is the breakaway: a rover at
  rest does not creep below ``(R / F_stall) / eta`` of power (or the deadband).
* **Tyre**, linear-saturating combined slip (friction ellipse). Slip ratio
  ``kappa = (u - v) / max(|v|, v_min)`` and lateral slip ``tan(alpha) = v_y / max(|v|, v_min)``
  give ``F_x = N kappa / c_x`` and ``F_y = -N tan(alpha) / c_y`` (``c_x``, ``c_y``: Gazebo's
  WheelSlip *slip compliances*, slip per unit of force/normal load); when
  ``(F_x / mu_x N)^2 + (F_y / mu_y N)^2 > 1`` both are scaled back onto that ellipse (a circle
  when the two grips are equal): the force keeps the direction of the combined slip and never
  exceeds ``mu N``. Slip at which the force saturates in pure longitudinal slip:
  ``kappa* = mu_x * c_x``.

Why linear-saturating rather than Pacejka's magic formula: it has two parameters a user can
measure (slip at saturation, friction), it is the slope and the plateau of the brush model, and
it can be integrated *implicitly in closed form*: the slip ODE is stiff (a 1 kg rim on a tyre
of stiffness ``N / (c_x |v|)`` relaxes in milliseconds at walking speed), so an explicit step
at 100 Hz would blow up, and sub-stepping would cost the hot loop several times over. The
magic formula's falling branch (``mu_peak > mu_slide``) would need an iterative solve per
wheel per step. What a linear-saturating tyre leaves out: the peak-then-drop of grip with slip
(here grip holds at ``mu N`` however hard the wheel spins) and relaxation length.

Integration, per physics step ``dt`` (semi-implicit, one pass; only a sliding tyre's rim is
found by bisection, :func:`slide`): the rim's speed
and the tyre force are solved together by backward Euler on the linear part —

    rim:   M_w (u+ - u) / dt = F0 - c (theta u+ + (1 - theta) u) - R_dir - F_x
                                                  (M_w = J / r^2, c = F_stall / v_free)
    body:  v+ = v + E F_x + E2 F_x'                           (F_x' the other wheel's force)
    tyre:  F_x = k (u+ - v+)                                  (k = N / (c_x max(|v|, v_min)))

with ``E = dt (1/m + h^2/I)`` and ``E2 = dt (1/m - h^2/I)`` (a wheel's force moves its own hub
and, through the body's yaw, the other one; ``theta``, about 1/2, from
:func:`emf_implicitness`, makes the body's motor time constant decay at its exact rate) — a 2 ×
2 linear system for the two tyre forces (:func:`wheel_pair`). Backward Euler is exact for that
linear system, stable at any stiffness, and turns into the rigid no-slip constraint as ``k``
grows (``v -> 0``). The nonlinear pieces are then applied as projections: the rim may not
reverse through zero against its resistance (it sticks instead, if the resistance can hold it),
the motor force is clamped by the current limit (the rim is then re-solved without back-EMF) —
in these rare branches each wheel is solved alone (:func:`rim_and_tyre`), the other's force
from the joint pass taken as known. A tyre that this gripping solve puts beyond its friction
ellipse *slides*: its force is then the tyre law itself, solved together with its rim by
:func:`slide` (scaling the gripping solve's forces onto the ellipse instead made a drift depend
on the physics step).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: Below this ground speed slips are measured against it (as PhysX's minimum slip
#: denominators): a wheel at rest has a finite, stiff tyre instead of a division by zero.
SLIP_SPEED_MIN = 0.1
#: Torque of a circular contact patch of radius ``a`` twisting under Coulomb friction:
#: ``(3 pi / 16) a mu N`` (Hertzian pressure; Gazebo's torsional friction with patch_radius).
TORSION = 3 * math.pi / 16


@dataclass(frozen=True)
class WheelModel:
    """One wheel's parameters in SI units, forces at the ground (N), speeds at the rim (m/s).

    ``load_n`` is the wheel's normal load; ``mu`` and ``crr`` of the ground come per call
    (terrain zones change them under the wheel).
    """

    stall_force_n: float
    free_speed_mps: float
    efficiency: float
    max_force_n: float
    deadband_pct: float
    joint_friction_n: float
    rim_mass_kg: float
    load_n: float
    slip_long: float
    slip_lat: float
    traction_coef: float = 1.0
    lateral_coef: float = 1.0
    rolling_coef: float = 1.0
    patch_radius_m: float = 0.0
    #: load transfer (``forces.rover_step``): the centre of mass's height (0: no transfer)
    #: and the signed distance from the caster to the drive axle along the heading
    com_height_m: float = 0.0
    wheelbase_m: float = 1.0
    #: m g / 2: a drive wheel's load with the caster lifted, and its share of the whole
    #: base's rolling resistance (the caster's drag reaches the ground through the drive
    #: tyres of a rigid base, so it is carried at their rims); 0: ``load_n``
    half_weight_n: float = 0.0
    gravity: float = 9.81
    #: the holding brake at the rim (N), engaged while the driver applies no voltage
    brake_force_n: float = 0.0

    # -- driver ---------------------------------------------------------------------------
    def command(self, power_pct: float) -> float:
        """The power the driver applies: 0 inside the deadband, else ``power_pct``."""
        return power_pct if abs(power_pct) >= self.deadband_pct else 0.0

    def drive_force(self, power_pct: float) -> float:
        """``F0 = F_stall eta p/100`` (N): the motor's force at rest, before the current limit."""
        return self.stall_force_n * self.efficiency * self.command(power_pct) * 0.01

    def back_emf(self) -> float:
        """``c = F_stall / v_free``: motor force lost per m/s of rim speed (N s/m)."""
        return self.stall_force_n / self.free_speed_mps

    def motor_force(self, power_pct: float, u: float) -> float:
        """Motor force at the ground (N) at rim speed ``u``, current-limited (the power
        supply's current draw reads it: ``robots.py``)."""
        f = self.drive_force(power_pct) - self.back_emf() * u
        return max(-self.max_force_n, min(self.max_force_n, f))

    # -- ground ---------------------------------------------------------------------------
    def resistance(self, crr: float) -> float:
        """``R = Crr rollingCoef m g / 2 + jointFriction / r`` (N at the rim) on ground ``crr``:
        each drive wheel carries half the rolling resistance of the whole base, the caster's
        included (``half_weight_n``), whatever share of the weight the caster bears."""
        rolling = self.half_weight_n if self.half_weight_n > 0.0 else self.load_n
        return crr * self.rolling_coef * rolling + self.joint_friction_n

    def grip(self, mu: float) -> tuple[float, float]:
        """Longitudinal and lateral force limits (N): the friction ellipse's half-axes."""
        return mu * self.traction_coef * self.load_n, mu * self.lateral_coef * self.load_n

    def scrub_limit(self, mu: float) -> float:
        """Largest twisting torque of the contact patch (N m): ``(3 pi/16) a mu_y N``."""
        return TORSION * self.patch_radius_m * mu * self.lateral_coef * self.load_n

    # -- closed forms ---------------------------------------------------------------------
    def steady_speed(self, power_pct: float, crr: float) -> float:
        """Top speed (m/s) at constant power on a straight line: ``F_m(v) = R``.

        ``v = v_free (eta p/100 - R / F_stall)`` (the current limit does not bind at a
        steady speed on the flat: the motor then only balances ``R < F_max``).
        """
        drive = self.drive_force(power_pct)
        res = self.resistance(crr)
        if abs(drive) <= res:
            return 0.0
        sign = 1.0 if drive > 0 else -1.0
        return (drive - sign * res) / self.back_emf()

    def power_for_speed(self, v: float, crr: float, force: float = 0.0) -> float:
        """Power (%) that holds a wheel's hub at ``v`` on ``crr`` while its tyre pushes the
        body with ``force`` (N): the inverse of steady_speed when ``force`` is 0.

        The rim turns faster than the hub by the tyre's slip ``force c_x max(|v|, v_min)/N``;
        the motor balances the resistance and the tyre: ``F_m(u) = R + force``.
        """
        if v == 0.0 or self.efficiency == 0.0:
            return 0.0
        u = v + force * self.slip_long * slip_speed(v) / self.load_n
        sign = 1.0 if u > 0 else -1.0
        drive = self.back_emf() * u + sign * self.resistance(crr) + force
        return 100.0 * drive / (self.stall_force_n * self.efficiency)

    def breakaway_power(self, crr: float) -> float:
        """Least power (%) that moves a wheel from rest: ``R / (eta F_stall)``, or the
        deadband if that is larger (and never below it: the driver outputs nothing there)."""
        static = 100.0 * self.resistance(crr) / (self.stall_force_n * self.efficiency)
        return max(static, self.deadband_pct)


# -- one step, per wheel (the reference the fast paths are checked against) -------------------
@dataclass(frozen=True)
class StepConstants:
    """What one step of one wheel needs besides its state, folded for speed.

    ``mw = M_w / dt``; ``big_b = 1 / (mw + c)`` (the rim's implicit compliance, back-EMF
    included); ``big_bc = 1 / mw`` (without it, when the current limit binds); ``e`` the
    contact point's velocity change per N of this wheel's force over one step, ``e2`` the
    other wheel's contact point's.
    """

    mw: float
    c: float
    f_max: float
    big_b: float
    big_bc: float
    e: float
    e2: float
    #: the back-EMF's explicit part, ``(1 - theta) c`` (``emf_implicitness``): the callers
    #: take ``c_exp u`` off the motor's force at rest, ``c`` above is the implicit ``theta c``
    c_exp: float = 0.0


def emf_implicitness(w: WheelModel, dt: float, mass: float) -> float:
    """``theta``: the share of the back-EMF taken at the step's end (the rest at its start).

    Backward Euler (``theta = 1``) damps the body's motor time constant ``tau = M / c``
    (``M = m / 2 + J / r^2`` a wheel's share of the rolling mass) too slowly by
    ``~dt / (2 tau)``: 2.3 % at 100 Hz for the default rover, so a coast-down stopped 2-4 %
    late. ``theta = (x - 1 + e^-x) / (x (1 - e^-x))`` with ``x = c dt / M`` makes the step's
    decay factor ``(1 - (1 - theta) x) / (1 + theta x)`` the exact ``e^-x`` for that mode
    (``~1/2 + x / 12``); steady states (top speed, roll-back, climb) are the same for every
    ``theta``. A rim spinning alone (its tyre sliding) has the much faster mode
    ``y = c dt / J_r``: ``theta >= 1 - 1/y`` keeps its factor non-negative (no ringing).
    """
    c = w.back_emf()
    x = c * dt / (0.5 * mass + w.rim_mass_kg)
    if x < 1e-3:
        theta = 0.5 + x / 12.0
    else:
        ex = math.exp(-x)
        theta = (x - 1.0 + ex) / (x * (1.0 - ex))
    y = c * dt / w.rim_mass_kg
    if y > 1.0:
        theta = max(theta, 1.0 - 1.0 / y)
    return min(theta, 1.0)


def step_constants(
    w: WheelModel, dt: float, mass: float, moment: float, half_track: float
) -> StepConstants:
    """Fold a wheel's parameters for a step of ``dt`` on a body of ``mass`` and ``moment``."""
    mw = w.rim_mass_kg / dt
    theta = emf_implicitness(w, dt, mass)
    c = theta * w.back_emf()
    return StepConstants(
        mw=mw,
        c=c,
        f_max=w.max_force_n,
        big_b=1.0 / (mw + c),
        big_bc=1.0 / mw,
        e=dt * (1.0 / mass + half_track * half_track / moment),
        e2=dt * (1.0 / mass - half_track * half_track / moment),
        c_exp=(1.0 - theta) * w.back_emf(),
    )


def _solve(
    u: float, v: float, f0: float, fr: float, k: float, s: StepConstants
) -> tuple[float, float]:
    """Backward-Euler rim + tyre with the resistance ``fr`` given; current limit applied."""
    a = (s.mw * u + f0 - fr) * s.big_b
    fx = k * (a - v) / (1.0 + k * (s.big_b + s.e))
    up = a - s.big_b * fx
    fm = f0 - s.c * up
    if fm > s.f_max or fm < -s.f_max:  # the driver's current limit: constant force
        lim = s.f_max if fm > 0 else -s.f_max
        a = u + (lim - fr) * s.big_bc
        fx = k * (a - v) / (1.0 + k * (s.big_bc + s.e))
        up = a - s.big_bc * fx
    return fx, up


def rim_and_tyre(
    u: float, v: float, f0: float, res: float, k: float, s: StepConstants
) -> tuple[float, float]:
    """One step of a wheel whose tyre grips: ``(F_x, u+)``, before the friction ellipse.

    ``u`` rim speed, ``v`` hub ground speed, ``f0`` the motor's force at rest (deadband
    applied, not yet limited), ``res`` the rim's resistance, ``k`` the tyre's stiffness
    ``N / (c_x max(|v|, v_min))``. A rim that would reverse through zero against its
    resistance, or that is at rest, sticks at zero if the resistance can hold it.
    """
    if u != 0.0:
        fx, up = _solve(u, v, f0, res if u > 0 else -res, k, s)
        if up * u > 0.0:
            return fx, up
    # at rest, or stopping within the step: can the resistance hold the rim at zero?
    fx = -k * v / (1.0 + k * s.e)  # the tyre against a still rim
    f0_lim = f0 if -s.f_max <= f0 <= s.f_max else (s.f_max if f0 > 0 else -s.f_max)
    need = f0_lim + s.mw * u - fx
    if -res <= need <= res:
        return fx, 0.0
    return _solve(u, v, f0, res if need > 0 else -res, k, s)


def joint(
    u: tuple[float, float],
    v: tuple[float, float],
    f0: tuple[float, float],
    fr: tuple[float, float],
    k: tuple[float, float],
    lim: tuple[int, int],
    s: StepConstants,
) -> tuple[float, float, float, float]:
    """Both rims and tyres by backward Euler, the resistances ``fr`` given: ``(F_xL, u_L+,
    F_xR, u_R+)``. ``lim`` per wheel: 0 the motor on its curve (back-EMF implicit), +-1
    current-limited (a constant ``+-F_max``)."""
    ab = []
    for ui, f0i, fri, li in zip(u, f0, fr, lim, strict=True):
        if li:
            ab.append((ui + (li * s.f_max - fri) * s.big_bc, s.big_bc))
        else:
            ab.append(((s.mw * ui + f0i - fri) * s.big_b, s.big_b))
    (al, bbl), (ar, bbr) = ab
    (vl, vr), (kl, kr) = v, k
    gl = 1.0 + kl * (bbl + s.e)
    gr = 1.0 + kr * (bbr + s.e)
    cl = kl * s.e2
    cr = kr * s.e2
    bl = kl * (al - vl)
    br = kr * (ar - vr)
    det = gl * gr - cl * cr
    fxl = (bl * gr - cl * br) / det
    fxr = (br * gl - cr * bl) / det
    return fxl, al - bbl * fxl, fxr, ar - bbr * fxr


def held(v: tuple[float, float], k: tuple[float, float], s: StepConstants) -> tuple[float, float]:
    """The tyre forces against two rims held still: the joint backward Euler solve with the
    rims fixed, ``F_i (1 + k_i E) + k_i E2 F_j = -k_i v_i`` (the body brought to rest)."""
    (vl, vr), (kl, kr) = v, k
    gl = 1.0 + kl * s.e
    gr = 1.0 + kr * s.e
    cl = kl * s.e2
    cr = kr * s.e2
    bl = -kl * vl
    br = -kr * vr
    det = gl * gr - cl * cr
    return (bl * gr - cl * br) / det, (br * gl - cr * bl) / det


def held_by(f0: float, fx: float, res: float, s: StepConstants) -> bool:
    """Whether a rim at rest stays there: its motor at rest (current-limited) less the tyre
    force is within its static resistance."""
    f0_lim = f0 if -s.f_max <= f0 <= s.f_max else (s.f_max if f0 > 0 else -s.f_max)
    return -res <= f0_lim - fx <= res


def wheel_pair(
    u: tuple[float, float],
    v: tuple[float, float],
    f0: tuple[float, float],
    res: tuple[float, float],
    k: tuple[float, float],
    s: StepConstants,
) -> tuple[float, float, float, float]:
    """One step of both wheels, tyres gripping: ``(F_xL, u_L+, F_xR, u_R+)``.

    Both rims at rest stay at rest if each one's resistance can hold it against its motor and
    the tyre force that keeps the rover still (:func:`held`; a parked rover costs one small
    solve). While both rims turn on, :func:`joint` solves them together, a wheel whose motor
    the solve finds beyond the current limit solved again as limited (at most twice: the
    usual case — no limit — needs one solve; ``forces.py`` inlines it and the parked case).
    Otherwise (a rim starting or stopping) each wheel is a Coulomb stick-slip decision
    (:func:`rim_and_tyre`), the two coupled by three Jacobi passes (each wheel's hub moved by
    the other's last force), which converge by a factor ``E2 / E`` <= 0.15 a pass.
    """
    ul, ur = u
    if ul == 0.0 and ur == 0.0:  # both rims at rest: do they stay? (a parked rover)
        fxl, fxr = held(v, k, s)
        if held_by(f0[0], fxl, res[0], s) and held_by(f0[1], fxr, res[1], s):
            return fxl, 0.0, fxr, 0.0
    fr = (
        res[0] if ul > 0.0 else -res[0] if ul < 0.0 else 0.0,
        res[1] if ur > 0.0 else -res[1] if ur < 0.0 else 0.0,
    )
    lim = (0, 0)
    for _ in range(3):
        fxl, upl, fxr, upr = joint(u, v, f0, fr, k, lim, s)
        new = tuple(
            li or (1 if fm > s.f_max else -1 if fm < -s.f_max else 0)
            for li, fm in ((lim[0], f0[0] - s.c * upl), (lim[1], f0[1] - s.c * upr))
        )
        if new == lim:
            break
        lim = (new[0], new[1])
    if upl * ul > 0.0 and upr * ur > 0.0:
        return fxl, upl, fxr, upr
    (vl, vr), (f0l, f0r), (rl, rr), (kl, kr) = v, f0, res, k
    fxl, upl = rim_and_tyre(ul, vl, f0l, rl, kl, s)
    fxr, upr = rim_and_tyre(ur, vr, f0r, rr, kr, s)
    for _ in range(2):
        (fxl, upl), (fxr, upr) = (
            rim_and_tyre(ul, vl + s.e2 * fxr, f0l, rl, kl, s),
            rim_and_tyre(ur, vr + s.e2 * fxl, f0r, rr, kr, s),
        )
    return fxl, upl, fxr, upr


def slip_speed(v: float) -> float:
    """``max(|v|, v_min)``: the speed slips are measured against."""
    return max(abs(v), SLIP_SPEED_MIN)
