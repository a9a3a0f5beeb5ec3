"""Wheel, tyre and grip forces of one rover for one step: the pure path's arithmetic.

The model per rover (``wheel.py`` states the wheel part and its closed forms):

* each wheel: motor and driver, spinning rim and tyre, solved together semi-implicitly
  (:func:`wheel.rim_and_tyre`) from the wheel's rim speed and its hub's ground speed
  ``v_fwd -/+ w * track/2``; the tyre forces' sum pushes along the heading, their difference
  turns the body;
* scrub: each tyre's contact patch resists the body's yaw with a turn-slip moment, linear in
  ``w / max(|v|, v_min)`` (stiffness ``(3 pi/16) a^2 N / c_x`` per wheel) and saturating at
  the patch's Coulomb torque ``(3 pi/16) a mu N``, integrated implicitly: when turning in place
  the moment is the full patch torque; at speed it is small, so steering while driving is not
  hampered;
* lateral grip, a tyre with cornering compliance ``c_y`` on both wheels, integrated implicitly
  (so at low speed it becomes the rigid non-holonomic constraint): it must turn the velocity
  with the body without doing work. pymunk integrates velocity first, then the angle with the
  new angular velocity, so the heading at the end of the step is ``a + w' dt``. The tyre
  forces act along the *mid-step* heading and its normal (so the two stay orthogonal and the
  friction ellipse bounds their sum), the grip sized from the sideways velocity at the
  *end-of-step* heading (in the rigid limit: a pure rotation of the velocity, speed kept
  exactly). Cancelling sideways velocity at the start-of-step heading instead bleeds speed in
  every turn, by an amount that depends on the physics rate;
* each wheel's longitudinal and lateral force are then projected onto its friction ellipse
  (``|F| <= mu N``); a wheel whose tyre saturates has its rim re-solved with that force.

Why inlined float arithmetic rather than calls into ``wheel.py``: at 100 Hz with two rovers
every microsecond per step is 3 % of the run, and a Python call costs about as much
as the arithmetic it wraps. The usual path (tyres gripping, rims turning, no current limit)
is inlined; the rare branches call ``wheel.py``'s functions. ``reference.reference_forces`` is the
same model written plainly; the tests check this code against it. :func:`rover_step` is the
pure path's one copy of the per-rover arithmetic (``fewrovers.FewRovers`` and ``fleet.Fleet``
call it; ``_step.c`` mirrors it in C, bit for bit). This module holds only that arithmetic
and the constants it folds (:func:`fold`, :func:`ground_list`); the bookkeeping of reading
the bodies, writing the forces and stepping the space is each force model's
(``force_model.py``).
"""

from __future__ import annotations

import dataclasses
import math
from array import array
from collections.abc import Callable, Sequence
from operator import attrgetter
from typing import Any, NamedTuple, TypeVar

from .rover import DiffDriveRover
from .scrub import patch_scrub
from .sliding import mid_step, slide_pair
from .wheel import (
    SLIP_SPEED_MIN,
    TORSION,
    step_constants,
    wheel_pair,
)

INV_SLIP_SPEED_MIN = 1.0 / SLIP_SPEED_MIN
#: Grip below this (N) counts as this: a zero friction gives a zero force, not 1/0.
GRIP_FLOOR_N = 1e-9
#: A drive wheel's relative load never falls below this (a lifted wheel keeps a trace of
#: grip rather than a 1/0)
LOAD_FLOOR = 1e-9
#: The gripping solve runs twice a step, the second time with the hubs moved by the yaw the
#: first one's scrub gives them (``rover_step``); the tests run a mutant with one pass.
GRIP_PASSES = (0, 1)
#: Whether a sliding tyre's load is the one its own drive force leaves (``rover_step``); the
#: tests run a mutant with the gripping solve's load.
SLIDING_LOAD = True


class Folded(NamedTuple):
    """One rover's force-model constants, folded once (and again after a parameter change)."""

    kp: float  # motor force at rest per % of power (N/%)
    c: float  # back-EMF: force lost per m/s of rim speed (N s/m)
    f_max: float  # current limit at the ground (N)
    mw: float  # rim mass / dt (kg/s)
    big_b: float  # the rim's implicit compliance 1 / (mw + c)
    big_be: float  # big_b + e
    e: float  # contact-point velocity change per N over a step
    e2: float  # the other wheel's contact point's
    kx: float  # tyre longitudinal stiffness times speed: N / c_x (N)
    ky: float  # lateral: N / c_y (N)
    half_track: float
    turn_k: float  # dt^2 / (2 I): heading change per N m (the trapezoid, bodyio.trapezoid)
    dt_i: float  # dt / I
    dt_m: float  # dt / m
    m_dt: float  # m / dt
    sphi: float  # turn-slip stiffness times speed per wheel: (3 pi/16) a^2 N / c_x
    ky_dt_m: float  # ky dt / m
    neg_m_dt: float  # -m / dt
    mass: float  # m: a slope's pull is m g
    xfer: (
        float  # load transfer: a drive wheel's relative load lost per N of drive force, z / (2 L N)
    )
    kmax: float  # the drive wheels' largest relative load: the caster lifted
    inv_g2: float  # 1 / g^2: a slope's cos from its pull
    c_exp: float  # the back-EMF's explicit part (wheel.emf_implicitness)
    brake: float  # the holding brake at the rim (N), while the driver applies no voltage


def fold(rover: DiffDriveRover, dt: float) -> Folded:
    """The folded constants of ``rover`` for a step of ``dt``."""
    w = rover.wheel
    s = step_constants(w, dt, rover.mass, rover.moment, rover.half_track)
    kx = w.load_n / w.slip_long
    return Folded(
        kp=w.stall_force_n * w.efficiency * 0.01,
        c=s.c,
        f_max=s.f_max,
        mw=s.mw,
        big_b=s.big_b,
        big_be=s.big_b + s.e,
        e=s.e,
        e2=s.e2,
        kx=kx,
        ky=w.load_n / w.slip_lat,
        half_track=rover.half_track,
        turn_k=0.5 * dt * dt / rover.moment,
        dt_i=dt / rover.moment,
        dt_m=dt / rover.mass,
        m_dt=rover.mass / dt,
        sphi=TORSION * w.patch_radius_m**2 * kx,
        ky_dt_m=w.load_n / w.slip_lat * dt / rover.mass,
        neg_m_dt=-rover.mass / dt,
        mass=rover.mass,
        xfer=w.com_height_m / (2.0 * w.wheelbase_m * w.load_n) if w.load_n > 0.0 else 0.0,
        kmax=w.half_weight_n / w.load_n if w.load_n > 0.0 else 1.0,
        inv_g2=1.0 / (w.gravity * w.gravity) if w.gravity > 0.0 else 0.0,
        c_exp=s.c_exp,
        brake=w.brake_force_n,
    )


_T = TypeVar("_T")
#: per wheel class: a getter of all its dataclass fields as one tuple (one C call)
_FIELDS: dict[type, Callable[[Any], tuple[Any, ...]]] = {}


def fold_key(rover: DiffDriveRover) -> tuple[type, bytes]:
    """Everything :func:`fold` and :func:`ground_terms` read of ``rover``, bit for bit: rovers
    with equal keys fold to the same constants (``-0.0`` and ``0.0``, or two NaNs, differ)."""
    w = rover.wheel
    kind = type(w)
    fields = _FIELDS.get(kind)
    if fields is None:
        if not dataclasses.is_dataclass(w):  # no known fields: this rover shares nothing
            return kind, id(rover).to_bytes(8, "little") + b"id"
        names = [f.name for f in dataclasses.fields(w)]
        fields = _FIELDS[kind] = attrgetter(names[0], names[0], *names[1:])  # always a tuple
    values = array("d", fields(w))
    values.extend((rover.mass, rover.moment, rover.half_track))
    return kind, values.tobytes()


def per_kind(rovers: Sequence[DiffDriveRover], make: Callable[[DiffDriveRover], _T]) -> list[_T]:
    """``[make(r) for r in rovers]``, calling ``make`` once per distinct :func:`fold_key`.

    Why: folding is ~10 µs a rover; a 1,000-car platoon has one kind of car, and folding
    each (twice, for the compiled fleet) was ~8 % of a 10 s run. The rows are shared
    objects: callers copy them into their arrays and never edit them.
    """
    made: dict[tuple[type, bytes], _T] = {}
    out = []
    for r in rovers:
        key = fold_key(r)
        row = made.get(key)
        if row is None:
            row = made[key] = make(r)
        out.append(row)
    return out


def ground_terms(rover: DiffDriveRover, mu: float, crr: float) -> tuple[float, float, float, float]:
    """One wheel's ground-dependent terms: ``1/grip_x, 1/grip_y, resistance, scrub limit``."""
    gx, gy = rover.wheel.grip(mu)
    return (
        1.0 / max(gx, GRIP_FLOOR_N),
        1.0 / max(gy, GRIP_FLOOR_N),
        rover.wheel.resistance(crr),
        rover.wheel.scrub_limit(mu),
    )


def ground_list(
    rover: DiffDriveRover,
    left: tuple[float, float],
    right: tuple[float, float],
    slope: tuple[float, float, float] = (1.0, 0.0, 0.0),
) -> list[float]:
    """``[1/gx_L, 1/gy_L, R_L, 1/gx_R, 1/gy_R, R_R, scrub_L + scrub_R, g_x, g_y]`` for
    (mu, crr) pairs under the wheels and the slope ``(cos(angle), g_x, g_y)`` under the rover
    (``terrain.Terrain.slope``): the ground carries ``cos(angle)`` of the weight, so grip,
    scrub and rolling resistance scale with it (``mu cos``, ``crr cos``: the same floats on
    the flat), and gravity pulls along the slope with ``(g_x, g_y)`` (m/s²)."""
    cos, gx, gy = slope
    il, jl, rl, tl = ground_terms(rover, left[0] * cos, left[1] * cos)
    ir, jr, rr, tr = ground_terms(rover, right[0] * cos, right[1] * cos)
    return [il, jl, rl, ir, jr, rr, tl + tr, gx, gy]


def rover_step(
    plan: tuple[Any, ...],
    gnd: Sequence[float],
    dt: float,
    angle: float,
    vx: float,
    vy: float,
    w: float,
    ul: float,
    ur: float,
    drive_l: float,
    drive_r: float,
) -> tuple[float, float, float, float, float]:
    """One rover's force for one step: ``(fx, fy, torque, u_left+, u_right+)``.

    The pure path's only copy of the per-rover arithmetic (``_step.c``'s ``rover_forces`` is
    its C twin, bit for bit): ``FewRovers`` and ``Fleet`` both call it. ``plan`` is
    :func:`fold`'s constants followed by the wheel's :class:`wheel.StepConstants`, ``gnd``
    :func:`ground_list`'s terms, ``drive_*`` the drivers' outputs (%, deadband applied).
    The usual path (tyres gripping, rims turning, no current limit) is inlined: at 100 Hz
    with two rovers every microsecond per step is 3 % of the run, and a Python call costs
    about as much as the arithmetic it wraps; the rare branches call ``wheel.py``.
    """
    (
        kp,
        c,
        fmax,
        mw,
        bb,
        bbe,
        e,
        e2,
        kx,
        ky,
        h,
        turn_k,
        dt_i,
        dt_m,
        _m_dt,
        sphi,
        ky_dt_m,
        neg_m_dt,
        mass,
        xfer,
        kmax,
        inv_g2,
        c_exp,
        brake,
        sc,
    ) = plan
    vmin = SLIP_SPEED_MIN
    ivmin = INV_SLIP_SPEED_MIN
    sin = math.sin
    cos = math.cos
    gax = gnd[7]
    gay = gnd[8]
    sloped = gax != 0.0 or gay != 0.0
    if sloped:  # the solves see the velocity gravity gives the body within the step
        vx = vx + gax * dt
        vy = vy + gay * dt
    co = cos(angle)
    si = sin(angle)
    v_fwd = vx * co + vy * si
    wh = w * h
    ixl, iyl, rl, ixr, iyr, rr, ts, _, _ = gnd
    # both rims and tyres, backward Euler (wheel.wheel_pair's usual branch)
    vl = v_fwd - wh
    vr = v_fwd + wh
    ivl = 1.0 / vl if vl > vmin else (-1.0 / vl if vl < -vmin else ivmin)
    ivr = 1.0 / vr if vr > vmin else (-1.0 / vr if vr < -vmin else ivmin)
    kl = kx * ivl
    kr = kx * ivr
    # the motor's force at rest less the back-EMF's explicit part (wheel.emf_implicitness)
    f0l = kp * drive_l - c_exp * ul
    f0r = kp * drive_r - c_exp * ur
    if brake != 0.0:  # the holding brake: more Coulomb resistance at a rim the driver leaves
        if drive_l == 0.0:
            rl = rl + brake
        if drive_r == 0.0:
            rr = rr + brake
    # the gripping solve twice: the second time with the hubs moved by the yaw the first
    # one's scrub gives them within the step (backward Euler on the hubs without it saw the
    # tyres' torque turn the body while the scrub cancelled it: a steady turn's yaw rate came
    # 0.6-0.9 % off the law at 100 Hz, a spin on ice slowly)
    vl0 = vl
    vr0 = vr
    scrub = 0.0
    for _ in GRIP_PASSES:
        vl = vl0 - scrub * dt_i * h
        vr = vr0 + scrub * dt_i * h
        rigid = False
        if ul == 0.0 and ur == 0.0:
            # a parked rover (wheel.held): the tyres hold the body against still rims; the
            # rims stay still if their resistance holds them against motor and tyre
            if sloped:
                # on a slope the tyres carry a steady load at rest, which a slip-rate tyre could
                # only carry by creeping at its slip floor (~0.3 mm/s at 2°): the tyre's static
                # deflection (not a state here) holds it, so the held body is held rigidly
                det = e * e - e2 * e2
                fxl = (e2 * vr - e * vl) / det
                fxr = (e2 * vl - e * vr) / det
            else:
                gl = 1.0 + kl * e
                gr = 1.0 + kr * e
                cl = kl * e2
                cr = kr * e2
                bl = -kl * vl
                br = -kr * vr
                det = gl * gr - cl * cr
                fxl = (bl * gr - cl * br) / det
                fxr = (br * gl - cr * bl) / det
            nl = (f0l if -fmax <= f0l <= fmax else (fmax if f0l > 0 else -fmax)) - fxl
            nr = (f0r if -fmax <= f0r <= fmax else (fmax if f0r > 0 else -fmax)) - fxr
            if -rl <= nl <= rl and -rr <= nr <= rr:
                upl = upr = 0.0
                rigid = sloped
            else:
                fxl, upl, fxr, upr = wheel_pair(
                    (ul, ur), (vl, vr), (f0l, f0r), (rl, rr), (kl, kr), sc
                )
        else:
            al = (mw * ul + f0l - (rl if ul > 0.0 else -rl if ul < 0.0 else 0.0)) * bb
            ar = (mw * ur + f0r - (rr if ur > 0.0 else -rr if ur < 0.0 else 0.0)) * bb
            gl = 1.0 + kl * bbe
            gr = 1.0 + kr * bbe
            cl = kl * e2
            cr = kr * e2
            bl = kl * (al - vl)
            br = kr * (ar - vr)
            det = gl * gr - cl * cr
            fxl = (bl * gr - cl * br) / det
            fxr = (br * gl - cr * bl) / det
            upl = al - bb * fxl
            upr = ar - bb * fxr
            fml = f0l - c * upl
            fmr = f0r - c * upr
            if not (
                upl * ul > 0.0 and upr * ur > 0.0 and -fmax <= fml <= fmax and -fmax <= fmr <= fmax
            ):
                fxl, upl, fxr, upr = wheel_pair(
                    (ul, ur), (vl, vr), (f0l, f0r), (rl, rr), (kl, kr), sc
                )
        # scrub: the patches' turn-slip moment, implicit in the yaw rate, each patch capped at its
        # Coulomb torque (scrub.patch_scrub; the caps in proportion to the patches' lateral grip)
        isum = ivl + ivr
        torque = (fxr - fxl) * h
        kphl = sphi * ivl
        kphr = sphi * ivr
        kphi = sphi * isum
        base = w + torque * dt_i
        den = 1.0 + kphi * dt_i
        scrub = -kphi * base / den
        wn = base / den
        ysum = iyl + iyr  # > 0 for any real ground (GRIP_FLOOR_N)
        tl = ts * iyr / ysum if ysum > 0.0 else 0.5 * ts
        tr = ts - tl
        if not (-tl <= kphl * wn <= tl and -tr <= kphr * wn <= tr):
            scrub = patch_scrub(w, torque, kphl, kphr, kphi, tl, tr, ts, dt_i)
        torque += scrub
    # predicted heading change over this step (the trapezoid: (w + w1) dt / 2, bodyio.trapezoid)
    turn = w * dt + torque * turn_k
    end = angle + turn
    mid = angle + 0.5 * turn
    cm = cos(mid)
    sm = sin(mid)
    # velocity after the drive force alone, and its sideways part at the end heading
    fx = fxl + fxr
    a = fx * dt_m
    side = (vy + a * sm) * cos(end) - (vx + a * cm) * sin(end)
    kd = ky_dt_m * isum
    if rigid:  # held on a slope: sideways too
        f_lat = neg_m_dt * side / cos(0.5 * turn)
    else:
        f_lat = neg_m_dt * side / cos(0.5 * turn) * kd / (1.0 + kd)
    fyl = f_lat * ivl / isum
    fyr = f_lat - fyl
    ftot = fxl + fxr
    # skip the transfer when no tyre can reach its ellipse whatever load it moves: k >= 1 - d
    # (d = |a F| bounds the change), so a tyre within (1 - d)^2 of the static ellipse stays
    # inside (the transfer's load only enters the ellipse and the slide)
    d = xfer * ftot if xfer * ftot > 0.0 else -(xfer * ftot)
    if sloped:
        d = d / math.sqrt(1.0 - (gax * gax + gay * gay) * inv_g2)
    t1 = fxl * ixl
    t2 = fyl * iyl
    t3 = fxr * ixr
    t4 = fyr * iyr
    room = (1.0 - d) * (1.0 - d) if d < 1.0 else 0.0
    ax = 0.0
    if xfer != 0.0 and (t1 * t1 + t2 * t2 > room or t3 * t3 + t4 * t4 > room):
        # load transfer: the drive force at the ground, below the centre of mass, moves load
        # between the drive wheels and the caster, k = N'/N = 1 - z F / (2 L N cos); the
        # force is first capped at the traction it can have with the load it leaves
        # (|F| <= G k(F): G / (1 +- z G / (2 L N cos))), so that a tyre sliding at its limit
        # sees its own load
        cs = math.sqrt(1.0 - (gax * gax + gay * gay) * inv_g2) if sloped else 1.0
        ax = xfer / cs
        aa = ax if ax > 0.0 else -ax
        gsum = 1.0 / ixl + 1.0 / ixr
        if ftot * ax > 0.0:
            lim = gsum / (1.0 + aa * gsum)
        elif aa * gsum < 1.0:
            lim = gsum / (1.0 - aa * gsum)
        else:
            lim = ftot if ftot > 0.0 else -ftot
        if ftot > lim:
            ftot = lim
        elif ftot < -lim:
            ftot = -lim
        k = 1.0 - ax * ftot
        if k > kmax:
            k = kmax
        elif k < LOAD_FLOOR:
            k = LOAD_FLOOR
        ik = 1.0 / k
        gxl = ixl
        gyl = iyl
        gxr = ixr
        gyr = iyr
        ixl = ixl * ik
        iyl = iyl * ik
        ixr = ixr * ik
        iyr = iyr * ik
        t1 = fxl * ixl
        t2 = fyl * iyl
        t3 = fxr * ixr
        t4 = fyr * iyr
    # friction ellipse per wheel: a tyre the gripping solve puts beyond it slides, and the
    # tyre law is solved with its rim instead (sliding.slide)
    sat_l = t1 * t1 + t2 * t2 > 1.0
    sat_r = t3 * t3 + t4 * t4 > 1.0
    if sat_l or sat_r:
        # the lateral force that cancels the body's sideways velocity within the step
        cancel = neg_m_dt * side / cos(0.5 * turn)
        left = (ul, vl, f0l, rl, ivl, ixl, iyl, fxl, fyl, upl)
        right = (ur, vr, f0r, rr, ivr, ixr, iyr, fxr, fyr, upr)
        pair = (sat_l, sat_r)
        tyre = (kx, ky, ky_dt_m)
        side0 = vy * co - vx * si
        # a predictor: the tyre law at the step's start (the slip of the body as it is now)
        fxl, fyl, upl, fxr, fyr, upr = slide_pair(pair, left, right, tyre, side0, cancel, sc)
        fx = fxl + fxr
        # the scrub again, implicit with the torque the tyres now give: the gripping solve's
        # forces are those that cancel each slip within the step (~1/dt), so its torque
        # saturated the scrub whatever the yaw rate
        torque = (fxr - fxl) * h
        torque += patch_scrub(w, torque, kphl, kphr, kphi, tl, tr, ts, dt_i)
        f_lat = fyl + fyr
        if ax != 0.0 and SLIDING_LOAD:
            # the load the sliding tyres' own drive force leaves the drive wheels: the
            # gripping solve's is the force that would cancel the slip within the step
            # (~1/dt, capped at the traction), not the one the ground gives (reference.py)
            k = 1.0 - ax * fx
            if k > kmax:
                k = kmax
            elif k < LOAD_FLOOR:
                k = LOAD_FLOOR
            ik = 1.0 / k
            left = (ul, vl, f0l, rl, ivl, gxl * ik, gyl * ik, *left[7:])
            right = (ur, vr, f0r, rr, ivr, gxr * ik, gyr * ik, *right[7:])
        # the sliding tyres' slip at the half step (sliding.mid_step): the body's velocity
        # and yaw rate moved on by half of what the predictor's forces give them, in the
        # frame of the heading half a step on; a rover spinning on ice turns under a
        # velocity that does not turn with it, while in a steady drift the same forces turn
        # the velocity with the body, so the slip stays the law's
        hub = mid_step(
            (vx, vy, w, angle),
            (fx * cm - f_lat * sm, fx * sm + f_lat * cm, torque),
            (dt, dt_m, dt_i, turn_k, h),
        )
        fxl, fyl, upl, fxr, fyr, upr = slide_pair(pair, left, right, tyre, side0, cancel, sc, hub)
        fx = fxl + fxr
        torque = (fxr - fxl) * h
        torque += patch_scrub(w, torque, kphl, kphr, kphi, tl, tr, ts, dt_i)
        f_lat = fyl + fyr
    fwx = fx * cm - f_lat * sm
    fwy = fx * sm + f_lat * cm
    if sloped:
        fwx = fwx + mass * gax
        fwy = fwy + mass * gay
    return fwx, fwy, torque, upl, upr


def too_fast(speed: float, max_speed: float) -> str:
    """The fault message for a body faster than ``physics.max_speed``."""
    return (
        f"body speed {speed:.3g} m/s exceeds physics.max_speed {max_speed:g} m/s (physics blow-up?)"
    )


def outside(x: float, y: float, extent: float) -> str:
    """The fault message for a body beyond ``physics.extent``."""
    return f"body left the world at ({x:.4g}, {y:.4g}) m (physics.extent is {extent:g} m)"
