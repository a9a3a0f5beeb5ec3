"""Wheel and grip forces for many rovers at once: one numpy pass, one batch read and write.

The same model and the same folded constants as ``forces.FewRovers`` (see ``forces.py``),
written over arrays. A step costs ~50 µs of numpy overhead plus ~0.3 µs a rover, where the
float path costs ~1.6 µs a rover (benchmarked on these machines: the float path wins up to
about 40 rovers), so ``PhysicsWorld`` switches at :data:`BATCH_MIN` rovers. The two paths
are checked against each other in the tests.
"""

from __future__ import annotations

import numpy as np

from .bodyio import BodyIO
from .forces import RoverConstants, constants, outside, too_fast
from .rover import DiffDriveRover

#: From this many rovers on, PhysicsWorld uses the numpy path.
BATCH_MIN = 40


class Fleet:
    """All rovers of one Space as arrays, indexed like ``rovers``."""

    def __init__(
        self, io: BodyIO, rovers: list[DiffDriveRover], dt: float, limits: tuple[float, float]
    ) -> None:
        self.io = io
        self.rovers = rovers
        self.dt = dt
        self.max_speed, self.extent = limits
        self.rows = np.array(io.rows, dtype=np.intp)
        self.powers = np.zeros((2, len(rovers)))
        for i, r in enumerate(rovers):
            r.attach_power_slot(self.powers, i)
        self._out = np.frombuffer(io.forces, dtype=np.float64).reshape(-1, 3)
        self.refresh()
        self.state = self.read()

    def refresh(self) -> None:
        """Re-read every rover's constants (after a parameter change: motor wear, ...).

        Folded exactly as ``FewRovers.refresh`` folds them, so both paths do the same
        arithmetic.
        """
        k = RoverConstants(*np.array([constants(r) for r in self.rovers]).T)
        dt = self.dt
        self.kp = k.stall * k.efficiency * 0.01
        self.kv = k.stall / k.free_speed
        self.traction = k.traction
        self.neg_traction = -k.traction
        self.rolling = k.rolling
        self.inv_veps = 1.0 / k.v_eps
        self.half_track = k.half_track
        self.turn_k = dt * dt / k.moment
        self.dt_m = dt / k.mass
        self.m_dt = k.mass / dt
        self.lateral = k.lateral
        self.neg_lateral = -k.lateral

    def kinematics(self, k: int) -> list[float]:
        """Rover ``k``'s six state floats after the last step."""
        return self.state[k].tolist()

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
        return self.io.read_array()[self.rows]

    def _wheel(self, power: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Each wheel's force: motor with back-EMF, capped by traction, minus rolling."""
        motor = self.kp * power
        motor -= self.kv * v
        np.minimum(motor, self.traction, out=motor)  # ufuncs: np.clip costs 3x as much
        np.maximum(motor, self.neg_traction, out=motor)
        ratio = v * self.inv_veps
        np.minimum(ratio, 1.0, out=ratio)
        np.maximum(ratio, -1.0, out=ratio)
        ratio *= self.rolling
        motor -= ratio
        return motor

    def apply(self, state: np.ndarray) -> None:
        """Write every rover's force and torque for this step into the batch buffer."""
        dt = self.dt
        angle, vx, vy, w = state[:, 2], state[:, 3], state[:, 4], state[:, 5]
        c = np.cos(angle)
        s = np.sin(angle)
        v_fwd = vx * c
        v_fwd += vy * s
        wh = w * self.half_track
        f_l = self._wheel(self.powers[0], v_fwd - wh)
        f_r = self._wheel(self.powers[1], v_fwd + wh)
        fx = f_l + f_r
        torque = f_r - f_l
        torque *= self.half_track
        turn = w * dt
        turn += torque * self.turn_k
        a = fx * self.dt_m
        # sideways velocity after the drive force, at the end-of-step heading
        end = angle + turn
        side = (vy + a * s) * np.cos(end)
        side -= (vx + a * c) * np.sin(end)
        half = 0.5 * turn
        f_lat = -self.m_dt * side
        f_lat /= np.cos(half)
        np.minimum(f_lat, self.lateral, out=f_lat)
        np.maximum(f_lat, self.neg_lateral, out=f_lat)
        mid = angle + half
        out = self._out
        rows = self.rows
        out[rows, 0] = fx * c - f_lat * np.sin(mid)
        out[rows, 1] = fx * s + f_lat * np.cos(mid)
        out[rows, 2] = torque

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
