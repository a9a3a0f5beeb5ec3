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
        n = len(rovers)
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

    def kinematics_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 6) state of the rovers at ``index`` after the last step."""
        return self.state[index]

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
        """Write every rover's force and torque for this step into the batch buffer.

        Both wheels go through the wheel model as one (2, n) array and the three headings
        (end, mid, half-turn) through one ``cos`` and one ``sin``: at 200 rovers numpy's
        per-call cost is still half of the step.
        """
        dt = self.dt
        angle, vx, vy, w = state[:, 2], state[:, 3], state[:, 4], state[:, 5]
        c = np.cos(angle)
        s = np.sin(angle)
        v_fwd = vx * c
        v_fwd += vy * s
        # wheel ground speeds, left row then right row
        v = self._sign * (w * self.half_track)
        v += v_fwd
        motor = self.kp * self.powers
        motor -= self.kv * v
        np.minimum(motor, self.traction, out=motor)  # ufuncs: np.clip costs 3x as much
        np.maximum(motor, self.neg_traction, out=motor)
        v *= self.inv_veps
        np.minimum(v, 1.0, out=v)
        np.maximum(v, -1.0, out=v)
        v *= self.rolling
        motor -= v
        f_l, f_r = motor
        fx = f_l + f_r
        torque = f_r - f_l
        torque *= self.half_track
        turn = w * dt
        turn += torque * self.turn_k
        a = fx * self.dt_m
        # end-of-step, mid-step heading and half the turn, in one cos and one sin
        heads = self._heads
        np.multiply(turn, 0.5, out=heads[2])
        np.add(angle, turn, out=heads[0])
        np.add(angle, heads[2], out=heads[1])
        cos = np.cos(heads)
        sin = np.sin(heads[:2])
        # sideways velocity after the drive force, at the end-of-step heading
        side = (vy + a * s) * cos[0]
        side -= (vx + a * c) * sin[0]
        f_lat = -self.m_dt * side
        f_lat /= cos[2]
        np.minimum(f_lat, self.lateral, out=f_lat)
        np.maximum(f_lat, self.neg_lateral, out=f_lat)
        out = self._out[self._span] if self._span is not None else self._gather
        np.subtract(fx * c, f_lat * sin[1], out=out[:, 0])
        np.add(fx * s, f_lat * cos[1], out=out[:, 1])
        out[:, 2] = torque
        if self._span is None:
            self._out[self.rows] = out

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
