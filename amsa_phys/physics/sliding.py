"""A sliding tyre solved with its rim: the tyre law where the gripping solve cannot hold.

Beside ``wheel.py``'s gripping solve (both rims and tyres by backward Euler), a tyre whose
forces leave its friction ellipse slides: :func:`slide` solves the tyre law together with
its rim's next speed, and :func:`slide_pair` solves the two tyres of a rover together (a
sliding tyre beside a gripping one, the sideways cap that stops a slide overshooting within
the step). ``forces.rover_step`` inlines the same arithmetic and ``_step.c`` mirrors it.
"""

from __future__ import annotations

import dataclasses
import math

from .wheel import SLIP_SPEED_MIN, StepConstants, rim_and_tyre

#: Bisection steps of :func:`slide`'s rim solve at most (a double's bracket is exhausted
#: sooner unless the root is within ~1e-30 of zero; the loop also stops there).
SLIDE_ITERATIONS = 100
#: :func:`slide` splits a step at the instant its tyre's slip changes sign unless that falls
#: within this share of either end (a crossing there moves the step's force by at most twice
#: this share of the grip)
SPLIT_MIN = 0.02


def slide(
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
    """One step of a wheel whose tyre slides: ``(F_x, F_y, u+)``, split where the slip flips.

    Where the rim passes its hub's speed within the step, the tyre's force flips sign there,
    from about ``+mu N`` to ``-mu N``; one solve over the step takes the slip at the rim's
    mid-step speed and gives the whole step one side's force. A strong motor reverses its rim
    through the hub's speed within one step (600 N on a 1 kg rim: 5.8 to 1.7 m/s past a
    3.2 m/s hub at 100 Hz), and the step's wrong share of the force left a yaw-rate offset
    that both tyres sliding never took back; its sign and size depended on where in a step
    the crossing fell, so a long manoeuvre's heading did not converge with the rate (0.142,
    0.047, 0.055 rad at 100-400 Hz). So such a step is split at the crossing, estimated from
    the one solve's straight path ``tau = (u - v) / (u - u+)``: :func:`slide_once` up to it
    and again from there, the forces weighted by time.
    """
    fx, fy, up = slide_once(u, v, f0, res, ivs, tyre, side, fy_cap, s)
    a = u - v
    b = up - v
    if a * b < 0.0:
        tau = a / (a - b)
        if SPLIT_MIN < tau < 1.0 - SPLIT_MIN:
            s1 = dataclasses.replace(s, mw=s.mw / tau)
            s2 = dataclasses.replace(s, mw=s.mw / (1.0 - tau))
            fx1, fy1, u1 = slide_once(u, v, f0, res, ivs, tyre, side, fy_cap, s1)
            fx2, fy2, up = slide_once(u1, v, f0, res, ivs, tyre, side, fy_cap, s2)
            fx = tau * fx1 + (1.0 - tau) * fx2
            fy = tau * fy1 + (1.0 - tau) * fy2
    return fx, fy, up


def slide_once(
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
    """One solve of a sliding tyre with its rim over a step (:func:`slide`): ``(F_x, F_y, u+)``.

    Why not the gripping solve scaled back onto the ellipse: the gripping solve's forces are
    the ones that would cancel each slip *within the step* (the longitudinal one through the
    1 kg rim, the lateral one through the whole body), so their ratio, and with it the
    direction of the scaled force, was set by the masses and the step instead of by the
    slip: a steady drift's yaw rate moved by 12 % between 100 and 1,600 Hz.
    Here the tyre law itself, ``F = (N kappa / c_x, -N tan(alpha) / c_y) / max(1, |q|)``
    with ``q`` the two forces over their grips (the friction ellipse), is solved with the
    rim's next speed: ``M_w (u+ - u) / dt = F_m(u+) - R sign(u+) - F_x((u + u+) / 2)``
    (backward Euler for the motor, on its curve or at its current limit, the rim stuck at zero
    if its resistance holds it; the tyre's slip at the rim's mid-step speed, the speed the
    body feels over the step: with the end-of-step speed a spinning-up or spinning-down rim on
    ice pushed the body by a whole step's change of slip too early, 0.008 rad of a long
    manoeuvre's heading at 100 Hz). A rim that passes through zero within the step meets its
    Coulomb resistance ``R sign(u)`` on both sides of zero, so the resistance is its mean over
    the rim's straight path from ``u`` to ``u+``, ``R (|u+| - |u|) / (u+ - u)``; and the rim
    stops there only if the resistance holds it *at rest* (``|F_m(0) - F_x(0)| <= R``). Before,
    the end speed's sign held for the whole step, and a rim whose backward Euler step ended
    within ``R dt / M_w`` of zero was held there even when the motor drove it on through: at
    each reversal the rim lost up to ``2 R dt`` of momentum, which the body kept as a yaw-rate
    offset while both tyres slid (0.005 rad of the long manoeuvre's heading at 100 Hz, and
    an order below one). The left side rises with ``u+`` (the mean resistance does too) and
    the right side falls, so the root is unique; bisection finds it, the same operations in C
    and Python. The hub
    speed ``v`` and the lateral slip ``side * ivs`` (sideways velocity over the slip speed)
    are the body's, held through the step (it is ~30 times the rim's mass): the caller passes
    them half a step on (:func:`mid_step`). The lateral force is capped by ``fy_cap``, the
    force that cancels the sideways velocity within the step, so that a slide ending within
    the step does not overshoot into the other side. ``tyre`` is ``(N / c_x, N / c_y,
    1 / grip_x, 1 / grip_y)``; ``ivs`` is ``1 / max(|v|, v_min)``.
    """
    kx, ky, ix, iy = tyre
    qy = -ky * side * ivs * iy

    def tyre_x(up: float) -> tuple[float, float]:
        """The tyre's longitudinal force and the ellipse's scale at rim speed ``up``."""
        fx = kx * (0.5 * (u + up) - v) * ivs
        qx = fx * ix
        qq = qx * qx + qy * qy
        scale = 1.0 / math.sqrt(qq) if qq > 1.0 else 1.0
        return fx * scale, scale

    f0_lim = f0 if -s.f_max <= f0 <= s.f_max else (s.f_max if f0 > 0 else -s.f_max)
    rest = f0_lim - tyre_x(0.0)[0]  # what moves the rim at rest, besides its resistance
    need = s.mw * u + rest
    # the side the rim ends on: it keeps its direction, or stops within the step (at rest:
    # whichever side the forces overcome the resistance on, none if it holds)
    if u > 0.0:
        side_up = 1 if need > res else -1
    elif u < 0.0:
        side_up = -1 if need < -res else 1
    else:
        side_up = 1 if need > res else (-1 if need < -res else 0)
    if side_up * u <= 0.0 and -res <= rest <= res:
        up = 0.0  # at rest, or stopped within the step, and the resistance holds it
    else:
        reach = (s.f_max + 1.0 / ix) / s.mw  # |F_m| <= f_max and |F_x| <= grip
        if side_up * u < 0.0:  # through zero: the mean resistance lets it go up to R further
            reach = reach + res / s.mw
        if side_up > 0:
            lo, hi, fr = 0.0, u + reach, res
        else:
            lo, hi, fr = u - reach, 0.0, -res
        # the excess ``M_w (u+ - u)/dt - F_m(u+) + R_dir + F_x(u+)``, zero at the step's rim
        # speed, written out in the loop (not through ``tyre_x``): the pure step spends most
        # of a skid's time here, ~50 halvings a solve, and the calls were most of that. The
        # same operations in the same order as ``_step.c``'s slide_excess: the same floats
        mw, c, f_max, abs_u, qy2 = s.mw, s.c, s.f_max, abs(u), qy * qy
        for _ in range(SLIDE_ITERATIONS):
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            fm = f0 - c * mid
            if fm > f_max:
                fm = f_max
            elif fm < -f_max:
                fm = -f_max
            # through zero within the step: the resistance's mean over the path
            fr_mid = res * (abs(mid) - abs_u) / (mid - u) if mid * u < 0.0 else fr
            fx = kx * (0.5 * (u + mid) - v) * ivs
            qx = fx * ix
            qq = qx * qx + qy2
            if qq > 1.0:
                fx = fx * (1.0 / math.sqrt(qq))
            if mw * (mid - u) - fm + fr_mid + fx > 0.0:
                hi = mid
            else:
                lo = mid
        up = 0.5 * (lo + hi)
    fx, scale = tyre_x(up)
    fy = -ky * side * ivs * scale
    if abs(fy_cap) < abs(fy):
        fy = fy_cap
    return fx, fy, up


def mid_step(
    body: tuple[float, float, float, float],
    force: tuple[float, float, float],
    k: tuple[float, float, float, float, float],
) -> tuple[float, float, float, float, float]:
    """The sliding tyres' slip half a step on: ``(v_L, 1/s_L, v_R, 1/s_R, v_side)``.

    A sliding tyre's force is explicit in the body's velocity (the body is ~30 times the rim's
    mass), so taking its slip from the step's start is forward Euler: a rover spinning at
    6 rad/s on ice turns 0.06 rad a step under a velocity that does not turn with it, and a
    long low-friction manoeuvre's heading came 0.059 rad off at 100 Hz. Taken in the frame
    half a step on *alone* it was 0.013 rad, but every steady drift moved 0.3-0.5 % off the
    tyre law, because there the tyres' forces turn the velocity with the body. So the body
    is moved on by half of what the step's predicted forces give it, velocity and yaw rate
    alike (the midpoint rule): in a steady drift the slip is the law's again (to 0.01 %),
    and the spin's frame turns under its velocity.

    ``body``: ``(v_x, v_y, w, heading)`` at the step's start (world frame); ``force``: the
    predictor's ``(F_x, F_y, torque)`` (world frame, scrub included); ``k``: ``(dt, dt/m,
    dt/I, dt^2/(2 I), track/2)``. ``1/s`` is ``1 / max(|v|, v_min)``.
    """
    vx, vy, w, angle = body
    qx, qy, torque = force
    dt, dt_m, dt_i, turn_k, h = k
    hv = 0.5 * dt_m
    mx = vx + qx * hv
    my = vy + qy * hv
    wm = w + 0.5 * torque * dt_i
    th = angle + 0.5 * w * dt + 0.25 * torque * turn_k
    c = math.cos(th)
    s = math.sin(th)
    mf = mx * c + my * s
    ml = mf - wm * h
    mr = mf + wm * h
    vmin = SLIP_SPEED_MIN
    jl = 1.0 / ml if ml > vmin else (-1.0 / ml if ml < -vmin else 1.0 / vmin)
    jr = 1.0 / mr if mr > vmin else (-1.0 / mr if mr < -vmin else 1.0 / vmin)
    return ml, jl, mr, jr, my * c - mx * s


def slide_pair(
    sat: tuple[bool, bool],
    left: tuple[float, ...],
    right: tuple[float, ...],
    tyre: tuple[float, float, float],
    side: float,
    cancel: float,
    s: StepConstants,
    mid: tuple[float, float, float, float, float] | None = None,
) -> tuple[float, float, float, float, float, float]:
    """Both wheels when at least one tyre slides: ``(F_xL, F_yL, u_L+, F_xR, F_yR, u_R+)``.

    Each sliding tyre's force is the tyre law solved with its rim (:func:`slide`); a wheel
    that still grips is solved again (:func:`rim_and_tyre`) with its hub moved by the sliding
    one's force through the yaw, not by the gripping solve's for it. The lateral
    force a gripping tyre gave in the gripping solve was its share (by stiffness) of the force
    that brings the body's sideways velocity to its implicit end value with *both* tyres
    gripping; once the other slides, that share is wrong, and capping the sliding tyre at its
    own share held its force far below the tyre law whenever the other hub ran slowly (its
    stiffness ``~1 / max(|v|, v_min)`` took nearly all the share): a heavy rover's drift
    settled 4 % off the law at every rate. So: no tyre, nor both together, pushes past
    ``cancel``, the force that cancels the sideways velocity within the step (no overshoot
    into the other side); a tyre that still grips takes, implicitly and with its own
    stiffness, what the sliding one leaves (``(cancel - F_s) k / (1 + k)``, ``k = N dt /
    (c_y m max(|v|, v_min))``), and slides too if that puts it beyond its ellipse.

    ``left``/``right``: ``(u, v, f0, res, ivs, 1/grip_x, 1/grip_y, F_x, F_y, u+)``, the last
    three the gripping solve's; ``tyre``: ``(N / c_x, N / c_y, N dt / (c_y m))``; ``side`` the
    sideways velocity at the step's start; ``mid`` (:func:`mid_step`) the sliding tyres' hub
    speeds, slip speeds and sideways velocity when they are not the step's start values (a
    gripping wheel's solve is implicit from the start: it keeps ``v`` and ``ivs``).
    """
    kx, ky, ky_dt_m = tyre
    sat_l, sat_r = sat
    ul, vl, f0l, rl, ivl, ixl, iyl, fxl, fyl, upl = left
    ur, vr, f0r, rr, ivr, ixr, iyr, fxr, fyr, upr = right
    # the sliding tyres' slip: the hubs' speeds, their slip speeds and the sideways velocity
    ml, jl, mr, jr, ms = mid if mid is not None else (vl, ivl, vr, ivr, side)
    if sat_l:
        fxl, fyl, upl = slide(ul, ml, f0l, rl, jl, (kx, ky, ixl, iyl), ms, cancel, s)
    if sat_r:
        fxr, fyr, upr = slide(ur, mr, f0r, rr, jr, (kx, ky, ixr, iyr), ms, cancel, s)
    # a gripping wheel again, its hub moved by the sliding one's force (the joint solve had
    # the other's gripping force, ~1/dt, which made this one's an O(1) error)
    if sat_l and not sat_r:
        fxr, upr = rim_and_tyre(ur, vr + s.e2 * fxl, f0r, rr, kx * ivr, s)
    elif sat_r and not sat_l:
        fxl, upl = rim_and_tyre(ul, vl + s.e2 * fxr, f0l, rl, kx * ivl, s)
    if not sat_r:  # the gripping tyre takes, implicitly, what the sliding one leaves
        kg = ky_dt_m * ivr
        fyr = (cancel - fyl) * kg / (1.0 + kg)
        t3 = fxr * ixr
        t4 = fyr * iyr
        if t3 * t3 + t4 * t4 > 1.0:
            sat_r = True
            fxr, fyr, upr = slide(ur, mr, f0r, rr, jr, (kx, ky, ixr, iyr), ms, cancel, s)
    elif not sat_l:
        kg = ky_dt_m * ivl
        fyl = (cancel - fyr) * kg / (1.0 + kg)
        t1 = fxl * ixl
        t2 = fyl * iyl
        if t1 * t1 + t2 * t2 > 1.0:
            sat_l = True
            fxl, fyl, upl = slide(ul, ml, f0l, rl, jl, (kx, ky, ixl, iyl), ms, cancel, s)
    if sat_l and sat_r:  # both sliding: together not past the cancelling force either
        f_lat = fyl + fyr
        if f_lat * cancel > 0.0 and abs(f_lat) > abs(cancel):
            q = cancel / f_lat
            fyl = fyl * q
            fyr = fyr * q
    return fxl, fyl, upl, fxr, fyr, upr
