"""Wheel, tyre and grip forces for many rovers at once: one numpy pass, one batch read and write.

The same model and the same folded constants as ``forces.FewRovers`` (see ``forces.py`` and
``wheel.py``), written over arrays: both wheels of every rover as (2, n) arrays, left row
first. The rare branches of the wheel model (a rim at rest or stopping, the current limit,
a saturated tyre) are computed only for the wheels that take them, with the same formulas.
A step costs ~80 µs of numpy overhead plus ~0.5 µs a rover, where the float path costs
~3 µs a rover (benchmarked on these machines), so ``PhysicsWorld`` switches at
:data:`BATCH_MIN` rovers. The two paths are checked against each other in the tests.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .bodyio import BodyIO
from .forces import Folded, fold, outside, too_fast
from .rover import DiffDriveRover
from .wheel import SLIP_SPEED_MIN

#: From this many rovers on, PhysicsWorld uses the numpy path.
BATCH_MIN = 40
#: Where ``forces.ground_list``'s seven terms go in :attr:`Fleet.ground`'s rows: the left and
#: right wheel of each term next to each other, so each term is one (2, n) view.
_GROUND_ROWS = [0, 2, 4, 1, 3, 5, 6]


class _Tiles(NamedTuple):
    """Per-wheel constants as (2, n) arrays: left row, right row."""

    kx: np.ndarray
    kp: np.ndarray
    mw_bb: np.ndarray
    big_b: np.ndarray
    big_be: np.ndarray
    e2: np.ndarray
    c: np.ndarray
    f_max: np.ndarray


class Fleet:
    """All rovers of one Space as arrays, indexed like ``rovers``."""

    def __init__(
        self,
        io: BodyIO,
        rovers: list[DiffDriveRover],
        dt: float,
        limits: tuple[float, float],
        grounds: list[list[float]],
    ) -> None:
        self.io = io
        self.rovers = rovers
        self.dt = dt
        self.max_speed, self.extent = limits
        self.rows = np.array(io.rows, dtype=np.intp)
        n = len(rovers)
        self.drives = np.zeros((2, n))
        for i, r in enumerate(rovers):
            r.attach_power_slot(self.drives, i)
        self.rims = np.zeros((2, n))
        self.ground = np.zeros((7, n))
        for k, terms in enumerate(grounds):
            self.set_ground(k, terms)
        self._out = np.frombuffer(io.forces, dtype=np.float64).reshape(-1, 3)
        start = int(self.rows[0]) if n else 0
        consecutive = n > 0 and bool((self.rows == np.arange(start, start + n)).all())
        self._span = slice(start, start + n) if consecutive else None
        self._gather = np.zeros((n, 3))  # forces when the rovers are not consecutive bodies
        self._heads = np.zeros((3, n))
        self._sign = np.array([[-1.0], [1.0]])
        self.refresh()
        self.state = self.read()

    def refresh(self) -> None:
        """Re-read every rover's constants (after a parameter change: motor wear, ...).

        Folded exactly as ``FewRovers.refresh`` folds them, so both paths do the same
        arithmetic.
        """
        f = Folded(*np.array([fold(r, self.dt) for r in self.rovers]).T)
        self.k = f
        self.half_track = f.half_track
        self.big_bc = 1.0 / f.mw  # the rim's compliance without back-EMF (current limit)
        two = np.ones((2, 1))
        self.tiles = _Tiles(
            kx=two * f.kx,
            kp=two * f.kp,
            mw_bb=two * (f.mw * f.big_b),
            big_b=two * f.big_b,
            big_be=two * f.big_be,
            e2=two * f.e2,
            c=two * f.c,
            f_max=two * f.f_max,
        )

    def set_ground(self, k: int, terms: list[float]) -> None:
        """Rover ``k``'s ground terms (``forces.ground_list``) from the next step on."""
        self.ground[_GROUND_ROWS, k] = terms

    def kinematics(self, k: int) -> list[float]:
        """Rover ``k``'s six state floats after the last step."""
        return self.state[k].tolist()

    def kinematics_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 6) state of the rovers at ``index`` after the last step."""
        return self.state[index]

    def rim_speeds(self, k: int) -> tuple[float, float]:
        """Rover ``k``'s left and right rim speeds (m/s) after the last step."""
        return float(self.rims[0, k]), float(self.rims[1, k])

    def rim_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 2) rim speeds of the rovers at ``index``."""
        return self.rims[:, index].T

    def advance(self) -> tuple[int, str] | None:
        """One physics step: forces, pymunk's step, the new state; a safety violation or None."""
        self.apply(self.state)
        self.io.write()
        self.io.step(self.dt)
        state = self.state = self.read()
        # the usual case in five array operations; NaN makes max() NaN, which fails
        vx, vy = state[:, 3], state[:, 4]
        speed2 = vx * vx
        speed2 += vy * vy
        if speed2.max() <= self.max_speed**2 and np.abs(state[:, :2]).max() <= self.extent:
            return None
        return self.first_violation(state, self.max_speed, self.extent)

    def read(self) -> np.ndarray:
        """(rovers, 6) array: x, y, angle, vx, vy, w now (a copy)."""
        raw = self.io.read_array()
        if self._span is not None:  # the rovers are consecutive bodies: a slice, no gather
            return raw[self._span].copy()
        return raw[self.rows]

    def apply(self, state: np.ndarray) -> None:
        """Write every rover's force and torque for this step and advance the rims.

        Written for numpy's fixed cost per call (~0.7 µs at 200 rovers, about the arithmetic
        of a rover): per-wheel constants are kept as (2, n) tiles (broadcasting costs twice),
        rows are filled in place rather than stacked, and the rare branches are looked for
        with one ``any()`` each.
        """
        f = self.k
        t = self.tiles
        n = len(self.rovers)
        dt = self.dt
        angle, vx, vy, w = state[:, 2], state[:, 3], state[:, 4], state[:, 5]
        c = np.cos(angle)
        s = np.sin(angle)
        v_fwd = vx * c
        v_fwd += vy * s
        # hub ground speeds, left row then right row, and the speeds slips are measured by
        wh = w * f.half_track
        v = np.empty((2, n))
        np.subtract(v_fwd, wh, out=v[0])
        np.add(v_fwd, wh, out=v[1])
        iv = np.abs(v)
        np.maximum(iv, SLIP_SPEED_MIN, out=iv)
        np.divide(1.0, iv, out=iv)
        k = t.kx * iv
        f0 = t.kp * self.drives
        u = self.rims
        ground = self.ground
        res = ground[4:6]
        # the usual branch, both wheels jointly: rims turning on, no current limit
        # (wheel.wheel_pair; a rim at rest takes the rare branch, whatever the sign here)
        a = t.mw_bb * u
        a += (f0 - np.copysign(res, u)) * t.big_b
        g = k * t.big_be
        g += 1.0
        cc = k * t.e2
        b = a - v
        b *= k
        det = g[0] * g[1]
        det -= cc[0] * cc[1]
        fx = np.empty((2, n))
        np.multiply(b[0], g[1], out=fx[0])
        fx[0] -= cc[0] * b[1]
        np.multiply(b[1], g[0], out=fx[1])
        fx[1] -= cc[1] * b[0]
        fx /= det
        up = a - t.big_b * fx
        fm = t.c * up
        fm -= f0
        np.abs(fm, out=fm)
        odd = up * u <= 0.0
        odd |= fm > t.f_max
        if odd.any():  # wheel.wheel_pair for those rovers
            rare = odd[0] | odd[1]
            parked = rare & (u[0] == 0.0) & (u[1] == 0.0)
            if parked.any():  # both rims at rest: held there? (wheel.held)
                # over all rovers, masked: a waiting column parks most of them at once, and
                # whole-array operations cost less than gathering them
                g = k * f.e
                g += 1.0
                cc = k * t.e2
                b = k * v
                fh = np.empty((2, n))
                np.multiply(cc[0], b[1], out=fh[0])
                fh[0] -= b[0] * g[1]
                np.multiply(cc[1], b[0], out=fh[1])
                fh[1] -= b[1] * g[0]
                fh /= g[0] * g[1] - cc[0] * cc[1]
                need = np.minimum(f0, t.f_max)
                np.maximum(need, -t.f_max, out=need)
                need -= fh
                np.abs(need, out=need)
                held = need <= res
                held = parked & held[0] & held[1]
                np.copyto(fx, fh, where=held)
                np.copyto(up, 0.0, where=held)
                rare &= ~held
            if rare.any():
                col = np.nonzero(rare)[0]
                fx[:, col], up[:, col] = _wheel_pair(
                    u[:, col], v[:, col], f0[:, col], res[:, col], k[:, col], f, col, self.big_bc
                )
        # scrub: the patches' turn-slip moment, implicit in the yaw rate, capped
        isum = iv[0] + iv[1]
        torque = fx[1] - fx[0]
        torque *= f.half_track
        kphi = f.sphi * isum
        scrub = torque * f.dt_i
        scrub += w
        scrub *= kphi
        scrub /= kphi * f.dt_i + 1.0
        np.negative(scrub, out=scrub)
        ts = ground[6]
        np.minimum(scrub, ts, out=scrub)
        np.maximum(scrub, -ts, out=scrub)
        torque += scrub
        turn = w * dt
        turn += torque * f.turn_k
        fxt = fx[0] + fx[1]
        acc = fxt * f.dt_m
        # end-of-step, mid-step heading and half the turn, in one cos and one sin
        heads = self._heads
        np.multiply(turn, 0.5, out=heads[2])
        np.add(angle, turn, out=heads[0])
        np.add(angle, heads[2], out=heads[1])
        cos = np.cos(heads)
        sin = np.sin(heads[:2])
        side_v = acc * sin[1]
        side_v += vy
        side_v *= cos[0]
        side_v -= (vx + acc * cos[1]) * sin[0]
        kd = f.ky_dt_m * isum
        f_lat = side_v * f.neg_m_dt
        f_lat /= cos[2]
        f_lat *= kd
        f_lat /= kd + 1.0
        fy = np.empty((2, n))
        np.multiply(f_lat, iv[0], out=fy[0])
        fy[0] /= isum
        np.subtract(f_lat, fy[0], out=fy[1])
        # friction ellipse per wheel; a rover with a saturated tyre has both rims re-solved
        tx = fx * ground[0:2]
        tx *= tx
        ty = fy * ground[2:4]
        ty *= ty
        tx += ty
        q = tx
        over = q > 1.0
        if over.any():
            col = np.nonzero(over[0] | over[1])[0]
            qc = q[:, col]
            scale = np.where(qc > 1.0, 1.0 / np.sqrt(np.maximum(qc, 1.0)), 1.0)
            fx[:, col] *= scale
            fy[:, col] *= scale
            cols = np.concatenate([col, col])
            sides = np.repeat([0, 1], len(col))
            up[sides, cols] = _rim_alone(
                u[sides, cols],
                f0[sides, cols],
                res[sides, cols],
                fx[sides, cols],
                f,
                cols,
                self.big_bc,
            )
            fxt = fx[0] + fx[1]
            torque = (fx[1] - fx[0]) * f.half_track + scrub
            f_lat = fy[0] + fy[1]
        out = self._out[self._span] if self._span is not None else self._gather
        np.multiply(fxt, cos[1], out=out[:, 0])
        out[:, 0] -= f_lat * sin[1]
        np.multiply(fxt, sin[1], out=out[:, 1])
        out[:, 1] += f_lat * cos[1]
        out[:, 2] = torque
        if self._span is None:
            self._out[self.rows] = out
        self.rims = up

    def first_violation(
        self, state: np.ndarray, max_speed: float, extent: float
    ) -> tuple[int, str] | None:
        """The first rover beyond the speed limit or the world's extent, and why."""
        speed = np.hypot(state[:, 3], state[:, 4])
        bad_speed = ~(speed <= max_speed)  # NaN counts as bad
        bad_place = ~((np.abs(state[:, 0]) <= extent) & (np.abs(state[:, 1]) <= extent))
        bad = bad_speed | bad_place
        if not bad.any():
            return None
        i = int(np.argmax(bad))
        if bad_speed[i]:
            return i, too_fast(float(speed[i]), max_speed)
        return i, outside(float(state[i, 0]), float(state[i, 1]), extent)


def _solve(
    u: np.ndarray,
    v: np.ndarray,
    f0: np.ndarray,
    fr: np.ndarray,
    k: np.ndarray,
    f: Folded,
    col: np.ndarray,
    big_bc: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """``wheel._solve`` for wheels of rovers ``col``: one rim + tyre, current limit applied."""
    mw, bb, c, fmax, e, bc = f.mw[col], f.big_b[col], f.c[col], f.f_max[col], f.e[col], big_bc[col]
    a = (mw * u + f0 - fr) * bb
    fx = k * (a - v) / (1.0 + k * (bb + e))
    up = a - bb * fx
    fm = f0 - c * up
    lim = (fm > fmax) | (fm < -fmax)
    if lim.any():
        a2 = u + (np.where(fm > 0, fmax, -fmax) - fr) * bc
        fx2 = k * (a2 - v) / (1.0 + k * (bc + e))
        fx = np.where(lim, fx2, fx)
        up = np.where(lim, a2 - bc * fx2, up)
    return fx, up


def _rim_and_tyre(
    u: np.ndarray,
    v: np.ndarray,
    f0: np.ndarray,
    res: np.ndarray,
    k: np.ndarray,
    f: Folded,
    col: np.ndarray,
    big_bc: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """``wheel.rim_and_tyre`` for wheels of rovers ``col`` (every branch, then chosen)."""
    fx1, up1 = _solve(u, v, f0, res * np.sign(u), k, f, col, big_bc)
    turning = (u != 0.0) & (up1 * u > 0.0)
    fxs = -k * v / (1.0 + k * f.e[col])
    fmax = f.f_max[col]
    need = np.clip(f0, -fmax, fmax) + f.mw[col] * u - fxs
    stick = (need >= -res) & (need <= res)
    fx2, up2 = _solve(u, v, f0, np.where(need > 0, res, -res), k, f, col, big_bc)
    fx = np.where(turning, fx1, np.where(stick, fxs, fx2))
    up = np.where(turning, up1, np.where(stick, 0.0, up2))
    return fx, up


def _wheel_pair(
    u: np.ndarray,
    v: np.ndarray,
    f0: np.ndarray,
    res: np.ndarray,
    k: np.ndarray,
    f: Folded,
    col: np.ndarray,
    big_bc: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """``wheel.wheel_pair`` for rovers ``col``: (2, m) arrays of forces and rim speeds."""
    mw, bb, c, fmax, e, e2 = f.mw[col], f.big_b[col], f.c[col], f.f_max[col], f.e[col], f.e2[col]
    bc = big_bc[col]
    # (parked rovers held at rest were taken out by the caller, as wheel_pair's first test)
    fr = res * np.sign(u)
    lim = np.zeros(u.shape)
    for _ in range(3):  # the joint solve, current-limited wheels found and fixed
        a = np.where(lim != 0, u + (lim * fmax - fr) * bc, (mw * u + f0 - fr) * bb)
        bw = np.where(lim != 0, bc, bb)
        g = 1.0 + k * (bw + e)
        cc = k * e2
        b = k * (a - v)
        det = g[0] * g[1] - cc[0] * cc[1]
        fx = np.stack([b[0] * g[1] - cc[0] * b[1], b[1] * g[0] - cc[1] * b[0]]) / det
        up = a - bw * fx
        fm = f0 - c * up
        lim = np.where(lim != 0, lim, np.where(fm > fmax, 1.0, np.where(fm < -fmax, -1.0, 0.0)))
    turning = (up * u > 0.0).all(axis=0)
    if turning.all():
        return fx, up
    # a rim at rest or stopping: per wheel, coupled by three Jacobi passes
    fx2, up2 = _rim_and_tyre(u, v, f0, res, k, f, col, big_bc)
    for _ in range(2):
        fx2, up2 = _rim_and_tyre(u, v + e2 * fx2[::-1], f0, res, k, f, col, big_bc)
    return np.where(turning, fx, fx2), np.where(turning, up, up2)


def _rim_alone(
    u: np.ndarray,
    f0: np.ndarray,
    res: np.ndarray,
    fx: np.ndarray,
    f: Folded,
    col: np.ndarray,
    big_bc: np.ndarray,
) -> np.ndarray:
    """``wheel.rim_alone`` for the wheels of rovers ``col``: the rim under a fixed tyre force."""
    mw, bb, c, fmax, bc = f.mw[col], f.big_b[col], f.c[col], f.f_max[col], big_bc[col]

    def solve(fr: np.ndarray) -> np.ndarray:
        up = (mw * u + f0 - fr - fx) * bb
        fm = f0 - c * up
        limited = u + (np.where(fm > 0, fmax, -fmax) - fr - fx) * bc
        return np.where((fm > fmax) | (fm < -fmax), limited, up)

    up1 = solve(res * np.sign(u))
    turning = (u != 0.0) & (up1 * u > 0.0)
    need = np.clip(f0, -fmax, fmax) + mw * u - fx
    stick = (need >= -res) & (need <= res)
    up2 = solve(np.where(need > 0, res, -res))
    return np.where(turning, up1, np.where(stick, 0.0, up2))
