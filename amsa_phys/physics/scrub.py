"""Tyre scrub: the turn-slip moment of the two contact patches when a rover yaws.

Its own concept beside the tyre law (``wheel.py``): the patches twist under the rover's yaw
rate, resisting it with a moment linear in the turn slip and capped at each patch's Coulomb
torque. :func:`scrub_moment` is the steady moment (the leader's kinematic model uses it);
:func:`patch_scrub` is one implicit step of it (the rovers' force model, and the C step's
twin of the same name).
"""

from __future__ import annotations

from .wheel import TORSION, WheelModel, slip_speed


def scrub_moment(
    w: float, v_l: float, v_r: float, model: WheelModel, mu_l: float, mu_r: float
) -> float:
    """Steady scrub moment (N m) on a rover turning at ``w`` with hub speeds ``v_l``, ``v_r``.

    Each tyre's patch resists the yaw with a turn-slip moment linear in ``w / max(|v|,
    v_min)`` of stiffness ``(3 pi/16) a^2 N / c_x`` (the brush model's: the same bristles
    that give the slip stiffness ``N / c_x``, twisted over a patch of radius ``a``), capped at
    the patch's Coulomb torque ``(3 pi/16) a mu N``. On a circle of radius ``R`` both wheels
    roll, so the moment is about ``(3 pi/8) a^2 N / (c_x R)``: small at speed, the full patch
    torque when turning in place (each wheel then rolls on a circle of radius track/2).
    """
    kx = model.load_n / model.slip_long
    kphi = TORSION * model.patch_radius_m**2 * kx * (1 / slip_speed(v_l) + 1 / slip_speed(v_r))
    limit = model.scrub_limit(mu_l) + model.scrub_limit(mu_r)
    return max(-limit, min(limit, -kphi * w))


def patch_scrub(
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
    """Both patches' turn-slip moment for one step, implicit in the yaw rate, each patch
    capped at its own Coulomb torque: the sum ``S`` with ``w+ = w + (torque + S) dt_i``,
    ``S_i = -k_i w+`` clamped to ``+-t_i``.

    Why per patch: capping the sum at ``t_l + t_r`` lets the slow hub's patch, whose turn-slip
    stiffness ``k_i ~ 1 / max(|v_i|, v_min)`` is the larger, twist past its own Coulomb
    torque whenever the fast hub's stays under its own: in a drift whose inner hub runs slowly
    the scrub was 2.7 N m (26 %) above the documented law's, and the drift settled 6 % off
    its yaw rate at every physics rate. ``k_i`` the turn-slip stiffness (N m s), ``t_i``
    the caps (N m), ``ts`` their sum as the caller has it (returned as such when both bind,
    so a turn in place keeps its bits), ``dt_i = dt / I``. The yaw rate is monotone in
    ``S``, so the patch with the lower threshold ``t_i / k_i`` saturates first.
    """
    base = w + torque * dt_i
    scrub = -ksum * base / (1.0 + ksum * dt_i)
    wn = base / (1.0 + ksum * dt_i)
    if -tl <= kl * wn <= tl and -tr <= kr * wn <= tr:
        return scrub
    if kl * tr >= kr * tl:
        t1, k2, t2 = tl, kr, tr
    else:
        t1, k2, t2 = tr, kl, tl
    s1 = -t1 if base > 0.0 else t1
    wn = (base + s1 * dt_i) / (1.0 + k2 * dt_i)
    s2 = -k2 * wn
    if s2 > t2 or s2 < -t2:  # both patches at their Coulomb torque
        return -ts if base > 0.0 else ts
    return s1 + s2
