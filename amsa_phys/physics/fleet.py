"""Wheel and grip forces for many rovers at once: one numpy pass, one batch read and write.

The same model as ``forces.FewRovers`` (see ``forces.py``) written over arrays. Per physics
step it costs one batch read, one batch write and ~40 numpy operations whatever the number of
rovers, where the float path costs ~1.5 µs a rover. numpy's fixed cost per operation makes
the float path cheaper for a handful of rovers, so ``PhysicsWorld`` switches at
:data:`BATCH_MIN` rovers. The two paths are checked against each other in the tests.
"""

from __future__ import annotations

import numpy as np

from .bodyio import BodyIO
from .forces import RoverConstants, constants, outside, too_fast
from .rover import DiffDriveRover

#: From this many rovers on, PhysicsWorld uses the numpy path.
BATCH_MIN = 6


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
        """Re-read every rover's constants (after a parameter change: motor wear, ...)."""
        k = RoverConstants(*np.array([constants(r) for r in self.rovers]).T)
        self.stall = k.stall
        self.inv_vfree = 1.0 / k.free_speed
        self.eff = k.efficiency * 0.01
        self.traction = k.traction
        self.rolling = k.rolling
        self.inv_veps = 1.0 / k.v_eps
        self.half_track = k.half_track
        self.mass = k.mass
        self.inv_moment = 1.0 / k.moment
        self.lateral = k.lateral

    def kinematics(self, k: int) -> list[float]:
        """Rover ``k``'s six state floats after the last step."""
        return self.state[k].tolist()

    def advance(self) -> tuple[int, str] | None:
        """One physics step: forces, pymunk's step, the new state; a safety violation or None."""
        self.apply(self.state, self.dt)
        self.io.write()
        self.io.step(self.dt)
        state = self.state = self.read()
        return self.first_violation(state, self.max_speed, self.extent)

    def read(self) -> np.ndarray:
        """(rovers, 6) array: x, y, angle, vx, vy, w now (a copy)."""
        return self.io.read_array()[self.rows]

    def _drive(self, power: np.ndarray, v: np.ndarray) -> np.ndarray:
        motor = self.stall * (self.eff * power - v * self.inv_vfree)
        np.clip(motor, -self.traction, self.traction, out=motor)
        return motor - self.rolling * np.clip(v * self.inv_veps, -1.0, 1.0)

    def apply(self, state: np.ndarray, dt: float) -> None:
        """Write every rover's force and torque for this step into the batch buffer."""
        angle, vx, vy, w = state[:, 2], state[:, 3], state[:, 4], state[:, 5]
        c = np.cos(angle)
        s = np.sin(angle)
        v_fwd = vx * c + vy * s
        h = self.half_track
        f_l = self._drive(self.powers[0], v_fwd - w * h)
        f_r = self._drive(self.powers[1], v_fwd + w * h)
        fx = f_l + f_r
        torque = (f_r - f_l) * h
        turn = (w + torque * self.inv_moment * dt) * dt
        end = angle + turn
        mid = angle + 0.5 * turn
        m = self.mass
        px = vx + fx * c / m * dt
        py = vy + fx * s / m * dt
        side = -px * np.sin(end) + py * np.cos(end)
        f_lat = -m * (side / np.cos(0.5 * turn)) / dt
        np.clip(f_lat, -self.lateral, self.lateral, out=f_lat)
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
