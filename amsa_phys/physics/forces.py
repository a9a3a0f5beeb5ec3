"""Wheel and grip forces for a few rovers: plain floats, one batch read and write a step.

The model per rover (``wheel.py`` states it per wheel, in closed form):

* each wheel's longitudinal force from its power and its ground speed
  (``v_fwd -/+ w * track/2``): motor with back-EMF, capped by traction, minus rolling
  resistance; their sum pushes along the heading, their difference turns the body;
* lateral grip is a non-holonomic constraint: it must turn the velocity with the body
  without doing work. pymunk integrates velocity first, then the angle with the new angular
  velocity, so the heading at the end of the step is ``a + w' dt``. The grip impulse is
  applied along the normal at the *mid-step* heading and sized so the end-of-step velocity
  has no sideways component at the *end-of-step* heading: a pure rotation of the velocity
  (speed kept exactly), capped by the tyres' grip (beyond it the rover skids). Cancelling
  sideways velocity at the start-of-step heading instead bleeds speed in every turn, by an
  amount that depends on the physics rate.

Why inlined float arithmetic rather than calls into ``WheelModel``: at 100 Hz with two
rovers every microsecond per step is 3 % of the run (issue 8), and a Python call costs about
as much as the arithmetic it wraps. ``WheelModel.drive_force`` and ``wheel.lateral_force``
stay the readable reference; the fidelity tests check this code against them, and
``fleet.py`` (numpy, for many rovers) against this.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

from .bodyio import FORCE, STATE, BodyIO
from .rover import DiffDriveRover


class RoverConstants(NamedTuple):
    """One rover's force-model constants, read once (and again after a parameter change)."""

    stall: float
    free_speed: float
    efficiency: float
    traction: float
    rolling: float
    v_eps: float
    half_track: float
    mass: float
    moment: float
    lateral: float


def constants(rover: DiffDriveRover) -> RoverConstants:
    """The constants the force model needs for ``rover``."""
    w = rover.wheel
    return RoverConstants(
        w.stall_force_n,
        w.free_speed_mps,
        w.efficiency,
        w.traction_limit_n,
        w.rolling_force_n,
        w.v_eps_mps,
        rover.half_track,
        rover.mass,
        rover.body.moment,
        rover.lateral_limit,
    )


class FewRovers:
    """The force model over plain floats for rovers at body ``rows`` of a batch state."""

    def __init__(self, io: BodyIO, rovers: list[DiffDriveRover]) -> None:
        self.io = io
        self.rovers = rovers
        self.rows = io.rows
        self.refresh()

    def refresh(self) -> None:
        """Re-read every rover's constants (after a parameter change: motor wear, ...)."""
        self._plan = [
            (r, row * STATE, row * FORCE, *constants(r))
            for r, row in zip(self.rovers, self.rows, strict=True)
        ]
        self._offsets = [row * STATE for row in self.rows]

    def kinematics(self, state: list[float], k: int) -> list[float]:
        """Rover ``k``'s six state floats."""
        i = self._plan[k][1]
        return state[i : i + STATE]

    def read(self) -> list[float]:
        """Every body's state now (see ``bodyio``), indexed through :attr:`rows`."""
        return self.io.read()

    def apply(self, state: Sequence[float], dt: float) -> None:
        """Write each rover's ``fx, fy, torque`` for this step into the batch buffer."""
        forces = self.io.forces
        sin = math.sin
        cos = math.cos
        for r, i, o, stall, vfree, eff, trac, roll, veps, h, mass, moment, lat in self._plan:
            angle = state[i + 2]
            vx = state[i + 3]
            vy = state[i + 4]
            w = state[i + 5]
            c = cos(angle)
            s = sin(angle)
            v_fwd = vx * c + vy * s
            # left wheel
            v = v_fwd - w * h
            motor = stall * (eff * r.power_l * 0.01 - v / vfree)
            if motor > trac:
                motor = trac
            elif motor < -trac:
                motor = -trac
            ratio = v / veps
            if ratio > 1.0:
                ratio = 1.0
            elif ratio < -1.0:
                ratio = -1.0
            f_l = motor - roll * ratio
            # right wheel
            v = v_fwd + w * h
            motor = stall * (eff * r.power_r * 0.01 - v / vfree)
            if motor > trac:
                motor = trac
            elif motor < -trac:
                motor = -trac
            ratio = v / veps
            if ratio > 1.0:
                ratio = 1.0
            elif ratio < -1.0:
                ratio = -1.0
            f_r = motor - roll * ratio
            fx = f_l + f_r
            torque = (f_r - f_l) * h
            # predicted heading change over this step (semi-implicit Euler, as pymunk does)
            turn = (w + torque / moment * dt) * dt
            end = angle + turn
            mid = angle + 0.5 * turn
            # velocity after the drive force alone, and its sideways part at the end heading
            px = vx + fx * c / mass * dt
            py = vy + fx * s / mass * dt
            side = px * -sin(end) + py * cos(end)
            f_lat = -mass * (side / cos(0.5 * turn)) / dt
            if f_lat > lat:
                f_lat = lat
            elif f_lat < -lat:
                f_lat = -lat
            forces[o] = fx * c + f_lat * -sin(mid)
            forces[o + 1] = fx * s + f_lat * cos(mid)
            forces[o + 2] = torque

    def first_violation(
        self, state: Sequence[float], max_speed: float, extent: float
    ) -> tuple[int, str] | None:
        """The first rover beyond the speed limit or the world's extent, and why."""
        max2 = max_speed * max_speed
        for k, i in enumerate(self._offsets):
            vx = state[i + 3]
            vy = state[i + 4]
            # written so that NaN fails every comparison
            if not (
                vx * vx + vy * vy <= max2
                and -extent <= state[i] <= extent
                and -extent <= state[i + 1] <= extent
            ):
                x, y = state[i], state[i + 1]
                speed = math.hypot(vx, vy)
                if not speed <= max_speed:
                    return k, too_fast(speed, max_speed)
                return k, outside(x, y, extent)
        return None


def too_fast(speed: float, max_speed: float) -> str:
    """The fault message for a body faster than ``physics.max_speed``."""
    return (
        f"body speed {speed:.3g} m/s exceeds physics.max_speed {max_speed:g} m/s (physics blow-up?)"
    )


def outside(x: float, y: float, extent: float) -> str:
    """The fault message for a body beyond ``physics.extent``."""
    return f"body left the world at ({x:.4g}, {y:.4g}) m (physics.extent is {extent:g} m)"
