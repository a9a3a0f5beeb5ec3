"""Wheel and grip forces for many rovers at once: one numpy pass, one batch read and write.

The same model as ``DiffDriveRover.apply_forces`` (see its docstring) written over arrays.
Per physics step it costs two ``pymunk.batch`` calls and ~40 numpy operations whatever the
number of rovers, where the per-rover path costs ~15 µs a rover (measurements.md: 200 rovers
at 6x real time). For a handful of rovers the per-rover path is cheaper (numpy's fixed cost
per operation), so ``PhysicsWorld`` switches at :data:`BATCH_MIN` rovers. The two paths are
checked against each other in the fidelity tests.

The post-step safety checks (``physics.max_speed``, ``physics.extent``) read the state the
next step reads anyway, so a blow-up is reported at the same instant as on the per-rover path.
"""

from __future__ import annotations

import array

import numpy as np
import pymunk
import pymunk.batch as pb

from .rover import DiffDriveRover

#: From this many rovers on, PhysicsWorld uses the batch path.
BATCH_MIN = 6

_READ = (
    pb.BodyFields.BODY_ID
    | pb.BodyFields.POSITION
    | pb.BodyFields.ANGLE
    | pb.BodyFields.VELOCITY
    | pb.BodyFields.ANGULAR_VELOCITY
)
_WRITE = pb.BodyFields.FORCE | pb.BodyFields.TORQUE


class Fleet:
    """All rovers of one Space, in the order the Space lists its bodies."""

    def __init__(self, space: pymunk.Space, rovers: list[DiffDriveRover]) -> None:
        self.space = space
        self.rovers = rovers
        self._in = pb.Buffer()
        pb.get_space_bodies(space, _READ, self._in)
        ids = np.frombuffer(memoryview(self._in.int_buf()).cast("P"), dtype=np.uintp)
        self.n_bodies = len(ids)
        row = {int(body_id): i for i, body_id in enumerate(ids)}
        self.rows = np.array([row[r.body.id] for r in rovers], dtype=np.intp)
        self.powers = np.zeros((2, len(rovers)))
        for i, r in enumerate(rovers):
            r.attach_power_slot(self.powers, i)
        self._out_array = array.array("d", bytes(8 * 3 * self.n_bodies))
        self._out_view = np.frombuffer(self._out_array, dtype=np.float64).reshape(-1, 3)
        self._out = pb.Buffer()
        self.refresh()

    def refresh(self) -> None:
        """Re-read every rover's parameters (after a parameter change: motor wear, ...)."""
        rs = self.rovers
        self.stall = np.array([r.wheel.stall_force_n for r in rs])
        self.inv_vfree = np.array([1.0 / r.wheel.free_speed_mps for r in rs])
        self.eff = np.array([r.wheel.efficiency * 0.01 for r in rs])
        self.traction = np.array([r.wheel.traction_limit_n for r in rs])
        self.rolling = np.array([r.wheel.rolling_force_n for r in rs])
        self.inv_veps = np.array([1.0 / r.wheel.v_eps_mps for r in rs])
        self.half_track = np.array([r.half_track for r in rs])
        self.mass = np.array([r.mass for r in rs])
        self.inv_moment = np.array([1.0 / r.body.moment for r in rs])
        self.lateral = np.array([r.lateral_limit for r in rs])

    def state(self) -> np.ndarray:
        """(rovers, 6) array: x, y, angle, vx, vy, w at this instant."""
        self._in.clear()
        pb.get_space_bodies(self.space, _READ, self._in)
        data = np.frombuffer(memoryview(self._in.float_buf()).cast("d"), dtype=np.float64)
        return data.reshape(-1, 6)[self.rows]

    def _drive(self, power: np.ndarray, v: np.ndarray) -> np.ndarray:
        motor = self.stall * (self.eff * power - v * self.inv_vfree)
        np.clip(motor, -self.traction, self.traction, out=motor)
        return motor - self.rolling * np.clip(v * self.inv_veps, -1.0, 1.0)

    def apply_forces(self, state: np.ndarray, dt: float) -> None:
        """Set every rover's force and torque for this step from ``state``."""
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
        out = self._out_view
        rows = self.rows
        out[rows, 0] = fx * c - f_lat * np.sin(mid)
        out[rows, 1] = fx * s + f_lat * np.cos(mid)
        out[rows, 2] = torque
        self._out.set_float_buf(self._out_array)
        pb.set_space_bodies(self.space, _WRITE, self._out)

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
            return i, (
                f"body speed {speed[i]:.3g} m/s exceeds physics.max_speed "
                f"{max_speed:g} m/s (physics blow-up?)"
            )
        x, y = state[i, 0], state[i, 1]
        return i, f"body left the world at ({x:.4g}, {y:.4g}) m (physics.extent is {extent:g} m)"
