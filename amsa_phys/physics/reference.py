"""The wheel, tyre and grip model of one rover written plainly: the tests' specification.

``forces.rover_step`` (and ``_step.c``, its C twin) compute the same forces with the usual
path inlined and constants folded for speed; this function reads pymunk's properties and
calls ``wheel.py``'s functions per wheel, so a reader can check the model line by line
against ``wheel.py``'s equations, and ``tests/engine/test_fast_paths.py`` holds the fast paths
to it in every regime. Slow (~10 µs a rover): it is also the "plain loop" of the benchmarks.
Flat ground only (a slope's terms are the fast paths' alone; ``tests/physics/test_slopes.py``
holds them to closed forms).
"""

from __future__ import annotations

import math

from .forces import GRIP_FLOOR_N, LOAD_FLOOR
from .rover import DiffDriveRover
from .sliding import mid_step, slide
from .wheel import (
    TORSION,
    WheelModel,
    rim_and_tyre,
    slip_speed,
    step_constants,
    wheel_pair,
)


def reference_forces(
    rover: DiffDriveRover,
    dt: float,
    rims: tuple[float, float],
    ground: tuple[tuple[float, float], tuple[float, float]],
) -> tuple[float, float, float, float, float]:
    """The same model written plainly: pymunk properties, ``wheel.py``'s functions per wheel.

    ``rims`` are the left and right rim speeds now, ``ground`` the ``(mu, crr)`` under each
    wheel. Returns ``(fx, fy, torque, u_left+, u_right+)``. Slow (~10 µs a rover); it is what
    the fast paths are tested against and the "plain loop" of the benchmarks.
    """
    body = rover.body
    wm = rover.wheel
    s = step_constants(wm, dt, rover.mass, body.moment, rover.half_track)
    a = body.angle
    c, sn = math.cos(a), math.sin(a)
    vx, vy = body.velocity
    w = body.angular_velocity
    v_fwd = vx * c + vy * sn
    kx = wm.load_n / wm.slip_long
    vl, vr = v_fwd - w * rover.half_track, v_fwd + w * rover.half_track
    sl, sr = slip_speed(vl), slip_speed(vr)
    (mul, crl), (mur, crr) = ground
    f0l, f0r = wm.drive_force(rover.power_l), wm.drive_force(rover.power_r)
    f0l, f0r = f0l - s.c_exp * rims[0], f0r - s.c_exp * rims[1]  # wheel.emf_implicitness
    rl, rr = wm.resistance(crl), wm.resistance(crr)
    # the holding brake: more Coulomb resistance at a rim the driver applies no voltage to
    rl += wm.brake_force_n if wm.command(rover.power_l) == 0.0 else 0.0
    rr += wm.brake_force_n if wm.command(rover.power_r) == 0.0 else 0.0
    ul, ur = rims
    sphi = TORSION * wm.patch_radius_m**2 * kx
    caps = (wm.scrub_limit(mul), wm.scrub_limit(mur))
    # the gripping solve, then again with the hubs moved by the yaw the scrub gives them
    # within the step (the scrub: the patches' turn-slip moment, implicit in the yaw rate)
    scrub = 0.0
    hub = (vl, vr)
    for _ in (0, 1):
        dv = scrub * dt / body.moment * rover.half_track
        hub = (vl - dv, vr + dv)
        fxl, upl, fxr, upr = wheel_pair((ul, ur), hub, (f0l, f0r), (rl, rr), (kx / sl, kx / sr), s)
        torque = (fxr - fxl) * rover.half_track
        scrub = _scrub(w, torque, (sphi / sl, sphi / sr), caps, dt / body.moment)
    torque += scrub
    vl, vr = sl, sr
    # lateral grip at the end-of-step heading, applied along the mid-step normal; the step
    # turns the body by the trapezoid of its yaw rates (bodyio.trapezoid)
    turn = (w + 0.5 * torque / body.moment * dt) * dt
    end, mid = a + turn, a + 0.5 * turn
    fx = fxl + fxr
    px = vx + fx * math.cos(mid) / rover.mass * dt
    py = vy + fx * math.sin(mid) / rover.mass * dt
    side = px * -math.sin(end) + py * math.cos(end)
    ky = wm.load_n / wm.slip_lat * (1 / vl + 1 / vr)
    kd = ky * dt / rover.mass
    f_lat = -rover.mass / dt * side / math.cos(0.5 * turn) * kd / (1 + kd)
    fyl = f_lat * (1 / vl) / (1 / vl + 1 / vr)
    fyr = f_lat - fyl
    # friction ellipses, on the load the drive force leaves the drive wheels
    gl, gr = wm.grip(mul), wm.grip(mur)
    inv = [1 / max(g, GRIP_FLOOR_N) for g in (*gl, *gr)]
    raw = inv
    k = load_factor(wm, fxl + fxr, 1 / inv[0] + 1 / inv[2])
    inv = [i / k for i in raw]
    sat = (fxl * inv[0]) ** 2 + (fyl * inv[1]) ** 2 > 1 or (fxr * inv[2]) ** 2 + (
        fyr * inv[3]
    ) ** 2 > 1
    if sat:  # a sliding tyre: the tyre law solved with its rim (sliding.slide)
        side0 = vy * math.cos(a) - vx * math.sin(a)
        # no tyre, nor both together, pushes past the force that cancels the sideways
        # velocity within the step
        cancel = -rover.mass / dt * side / math.cos(0.5 * turn)
        grip = (fxl, fyl, upl, fxr, fyr, upr)
        rims = ((ul, ur), hub, (f0l, f0r), (rl, rr), (sl, sr))

        def slide(
            inv: list[float], at: tuple[float, float, float, float, float] | None
        ) -> tuple[float, float, float, float, float, float, float]:
            return _slide_both(rover, dt, *rims, inv, grip, side0, cancel, (w, sphi, caps), at)

        # the tyre law at the step's start predicts the forces; the sliding tyres' slip is
        # then taken half a step on (sliding.mid_step) and the tyres solved again
        fxl, fyl, upl, fxr, fyr, upr, torque = slide(inv, None)
        f_lat = fyl + fyr
        fx = fxl + fxr
        # the load the sliding tyres' own drive force leaves the drive wheels
        a_load = wm.com_height_m / (2 * wm.wheelbase_m * wm.load_n)
        if a_load != 0:
            k = max(LOAD_FLOOR, min(wm.half_weight_n / wm.load_n, 1 - a_load * fx))
            inv = [i / k for i in raw]
        qx = fx * math.cos(mid) - f_lat * math.sin(mid)
        qy = fx * math.sin(mid) + f_lat * math.cos(mid)
        k = (dt, dt / rover.mass, dt / body.moment, dt * dt / (2 * body.moment), rover.half_track)
        at_mid = mid_step((vx, vy, w, a), (qx, qy, torque), k)
        fxl, fyl, upl, fxr, fyr, upr, torque = slide(inv, at_mid)
        fx = fxl + fxr
        f_lat = fyl + fyr
    return (
        fx * math.cos(mid) - f_lat * math.sin(mid),
        fx * math.sin(mid) + f_lat * math.cos(mid),
        torque,
        upl,
        upr,
    )


def _slide_both(
    rover: DiffDriveRover,
    dt: float,
    rims: tuple[float, float],
    hub: tuple[float, float],
    f0: tuple[float, float],
    res: tuple[float, float],
    slip: tuple[float, float],
    inv: list[float],
    grip: tuple[float, float, float, float, float, float],
    side0: float,
    cancel: float,
    yaw: tuple[float, float, tuple[float, float]],
    at_mid: tuple[float, float, float, float, float] | None,
) -> tuple[float, float, float, float, float, float, float]:
    """Both wheels when a tyre slides (``sliding.slide_pair``, written plainly):
    ``(F_xL, F_yL, u_L+, F_xR, F_yR, u_R+, torque)``, the torque with the scrub solved again.
    ``at_mid``: the sliding tyres' hub speeds, slip speeds and sideways velocity
    (``sliding.mid_step``), or None for the step's start."""
    wm = rover.wheel
    s = step_constants(wm, dt, rover.mass, rover.body.moment, rover.half_track)
    kx = wm.load_n / wm.slip_long
    ky1 = wm.load_n / wm.slip_lat
    ul, ur = rims
    f0l, f0r = f0
    rl, rr = res
    sl, sr = slip
    w, sphi, caps = yaw
    fxl, fyl, upl, fxr, fyr, upr = grip
    if at_mid is None:
        at_mid = (hub[0], 1 / sl, hub[1], 1 / sr, side0)
    out = [(fxl, fyl, upl), (fxr, fyr, upr)]
    slid = [
        (fxl * inv[0]) ** 2 + (fyl * inv[1]) ** 2 > 1,
        (fxr * inv[2]) ** 2 + (fyr * inv[3]) ** 2 > 1,
    ]
    args = [(ul, hub[0], f0l, rl, 1 / sl), (ur, hub[1], f0r, rr, 1 / sr)]
    sliding_args = [
        (ul, at_mid[0], f0l, rl, at_mid[1]),
        (ur, at_mid[2], f0r, rr, at_mid[3]),
    ]
    side_mid = at_mid[4]
    for i in (0, 1):
        if slid[i]:
            tyre = (kx, ky1, inv[2 * i], inv[2 * i + 1])
            out[i] = slide(*sliding_args[i], tyre, side_mid, cancel, s)
    if slid[0] != slid[1]:  # the gripping wheel again, its hub moved by the sliding force
        i = 0 if slid[1] else 1
        u_i, hub_i, f0_i, r_i, iv_i = args[i]
        fx_i, up_i = rim_and_tyre(u_i, hub_i + s.e2 * out[1 - i][0], f0_i, r_i, kx * iv_i, s)
        out[i] = (fx_i, out[i][1], up_i)
    for i in (0, 1):  # a gripping tyre takes, implicitly, what the sliding one leaves
        if slid[1 - i] and not slid[i]:
            kg = ky1 / (sl, sr)[i] * dt / rover.mass
            fy = (cancel - out[1 - i][1]) * kg / (1 + kg)
            out[i] = (out[i][0], fy, out[i][2])
            if (out[i][0] * inv[2 * i]) ** 2 + (fy * inv[2 * i + 1]) ** 2 > 1:
                slid[i] = True
                tyre = (kx, ky1, inv[2 * i], inv[2 * i + 1])
                out[i] = slide(*sliding_args[i], tyre, side_mid, cancel, s)
    (fxl, fyl, upl), (fxr, fyr, upr) = out
    if all(slid) and (fyl + fyr) * cancel > 0 and abs(fyl + fyr) > abs(cancel):
        fyl, fyr = fyl * cancel / (fyl + fyr), fyr * cancel / (fyl + fyr)
    # the scrub again, with the torque the tyres now give
    torque = (fxr - fxl) * rover.half_track
    torque += _scrub(w, torque, (sphi / sl, sphi / sr), caps, dt / rover.body.moment)
    return fxl, fyl, upl, fxr, fyr, upr, torque


def load_factor(wm: WheelModel, force: float, grip: float) -> float:
    """A drive wheel's load over its static load under drive force ``force`` (N, both
    wheels) on the flat: pitch balance about the centre of mass gives
    ``N = N0 - z F / (2 L)``; ``F`` first capped at the traction ``|F| <= grip N / N0`` the
    load it leaves allows; between the load floor and the caster lifted (m g / 2)."""
    if wm.com_height_m == 0.0:
        return 1.0
    a = wm.com_height_m / (2 * wm.wheelbase_m * wm.load_n)
    if force * a > 0:
        cap = grip / (1 + abs(a) * grip)
    elif abs(a) * grip < 1:
        cap = grip / (1 - abs(a) * grip)
    else:
        cap = abs(force)
    f = max(-cap, min(cap, force))
    return max(LOAD_FLOOR, min(wm.half_weight_n / wm.load_n, 1 - a * f))


def _scrub(
    w: float, torque: float, k: tuple[float, float], caps: tuple[float, float], dt_i: float
) -> float:
    """The patches' turn-slip moments, implicit in the yaw rate, each clamped to its own cap:
    found plainly by bisection on the end-of-step yaw rate (the moment falls as it rises)."""

    def excess(wn: float) -> float:
        s = sum(max(-c, min(c, -ki * wn)) for ki, c in zip(k, caps, strict=True))
        return wn - w - (torque + s) * dt_i

    lo, hi = -1e6, 1e6
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if excess(mid) > 0:
            hi = mid
        else:
            lo = mid
    wn = 0.5 * (lo + hi)
    return sum(max(-c, min(c, -ki * wn)) for ki, c in zip(k, caps, strict=True))
