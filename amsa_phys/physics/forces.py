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

import numpy as np

from .bodyio import FORCE, STATE, BodyIO
from .rover import DiffDriveRover
from .wheel import lateral_force


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
    """The force model over plain floats for rovers at body ``rows`` of a batch state.

    Constants are folded per rover once (``stall * efficiency``, ``dt / mass``, ...), so a
    step is ~45 float operations and seven trig calls a rover.
    """

    def __init__(
        self, io: BodyIO, rovers: list[DiffDriveRover], dt: float, limits: tuple[float, float]
    ) -> None:
        self.io = io
        self.rovers = rovers
        self.rows = io.rows
        self.dt = dt
        self.max_speed, self.extent = limits
        self._max2 = self.max_speed * self.max_speed * (1 - 1e-12)  # never above hypot's test
        self.refresh()
        self.state = io.read()

    def refresh(self) -> None:
        """Re-read every rover's constants (after a parameter change: motor wear, ...)."""
        dt = self.dt
        self._plan = []
        for r, row in zip(self.rovers, self.rows, strict=True):
            k = constants(r)
            self._plan.append(
                (
                    r,
                    row * STATE,
                    row * FORCE,
                    k.stall * k.efficiency * 0.01,  # force per % of power
                    k.stall / k.free_speed,  # back-EMF: force lost per m/s
                    k.traction,
                    k.rolling,
                    1.0 / k.v_eps,
                    k.half_track,
                    dt * dt / k.moment,  # heading change per N m of torque
                    dt / k.mass,  # velocity change per N
                    k.mass / dt,  # force that cancels 1 m/s in one step
                    k.lateral,
                )
            )
        self._offsets = [row * STATE for row in self.rows]

    def kinematics(self, k: int) -> list[float]:
        """Rover ``k``'s six state floats after the last step."""
        i = self._offsets[k]
        return self.state[i : i + STATE]

    def kinematics_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 6) state of the rovers at ``index`` after the last step."""
        rows = np.asarray(self.rows)[index]
        return np.array(self.state).reshape(-1, STATE)[rows]

    def advance(self) -> tuple[int, str] | None:
        """One physics step: forces, pymunk's step, the new state; a safety violation or None."""
        io = self.io
        self.apply(self.state)
        io.write()
        io.step(self.dt)
        state = self.state = io.read()
        # the safety check, inline: written so that NaN fails every comparison
        max2 = self._max2
        extent = self.extent
        for i in self._offsets:
            vx = state[i + 3]
            vy = state[i + 4]
            if not (
                vx * vx + vy * vy <= max2
                and -extent <= state[i] <= extent
                and -extent <= state[i + 1] <= extent
            ):
                return self.first_violation(state, self.max_speed, extent)
        return None

    def apply(self, state: Sequence[float]) -> None:
        """Write each rover's ``fx, fy, torque`` for this step into the batch buffer."""
        forces = self.io.forces
        dt = self.dt
        sin = math.sin
        cos = math.cos
        for r, i, o, kp, kv, trac, roll, inv_veps, h, turn_k, dt_m, m_dt, lat in self._plan:
            angle = state[i + 2]
            vx = state[i + 3]
            vy = state[i + 4]
            w = state[i + 5]
            c = cos(angle)
            s = sin(angle)
            v_fwd = vx * c + vy * s
            wh = w * h
            # left wheel: motor with back-EMF, capped by traction, minus rolling resistance
            v = v_fwd - wh
            motor = kp * r.power_l - kv * v
            if motor > trac:
                motor = trac
            elif motor < -trac:
                motor = -trac
            ratio = v * inv_veps
            if ratio > 1.0:
                ratio = 1.0
            elif ratio < -1.0:
                ratio = -1.0
            f_l = motor - roll * ratio
            # right wheel
            v = v_fwd + wh
            motor = kp * r.power_r - kv * v
            if motor > trac:
                motor = trac
            elif motor < -trac:
                motor = -trac
            ratio = v * inv_veps
            if ratio > 1.0:
                ratio = 1.0
            elif ratio < -1.0:
                ratio = -1.0
            f_r = motor - roll * ratio
            fx = f_l + f_r
            torque = (f_r - f_l) * h
            # predicted heading change over this step (semi-implicit Euler, as pymunk does)
            turn = w * dt + torque * turn_k
            end = angle + turn
            mid = angle + 0.5 * turn
            # velocity after the drive force alone, and its sideways part at the end heading
            a = fx * dt_m
            side = (vy + a * s) * cos(end) - (vx + a * c) * sin(end)
            f_lat = -m_dt * side / cos(0.5 * turn)
            if f_lat > lat:
                f_lat = lat
            elif f_lat < -lat:
                f_lat = -lat
            forces[o] = fx * c - f_lat * sin(mid)
            forces[o + 1] = fx * s + f_lat * cos(mid)
            forces[o + 2] = torque

    def first_violation(
        self, state: Sequence[float], max_speed: float, extent: float
    ) -> tuple[int, str] | None:
        """The first rover beyond the speed limit or the world's extent, and why."""
        for k, i in enumerate(self._offsets):
            x, y, _, vx, vy, _ = state[i : i + STATE]
            speed = math.hypot(vx, vy)
            if not speed <= max_speed:  # also catches NaN
                return k, too_fast(speed, max_speed)
            if not (abs(x) <= extent and abs(y) <= extent):
                return k, outside(x, y, extent)
        return None


def reference_forces(rover: DiffDriveRover, dt: float) -> tuple[float, float, float]:
    """The same model written plainly: pymunk properties, ``wheel.py``'s functions per wheel.

    ``(fx, fy, torque)`` for ``rover`` this step. Slow (~5 µs a rover); it is what the fast
    paths are tested against and the "plain loop" of the benchmarks.
    """
    body = rover.body
    a = body.angle
    c, s = math.cos(a), math.sin(a)
    vx, vy = body.velocity
    w = body.angular_velocity
    v_fwd = vx * c + vy * s
    f_l = rover.wheel.drive_force(rover.power_l, v_fwd - w * rover.half_track)
    f_r = rover.wheel.drive_force(rover.power_r, v_fwd + w * rover.half_track)
    fx = f_l + f_r
    torque = (f_r - f_l) * rover.half_track
    turn = (w + torque / body.moment * dt) * dt
    end, mid = a + turn, a + 0.5 * turn
    px = vx + fx * c / rover.mass * dt
    py = vy + fx * s / rover.mass * dt
    side = px * -math.sin(end) + py * math.cos(end)
    f_lat = lateral_force(side / math.cos(0.5 * turn), rover.mass, dt, rover.lateral_limit)
    return fx * c - f_lat * math.sin(mid), fx * s + f_lat * math.cos(mid), torque


def too_fast(speed: float, max_speed: float) -> str:
    """The fault message for a body faster than ``physics.max_speed``."""
    return (
        f"body speed {speed:.3g} m/s exceeds physics.max_speed {max_speed:g} m/s (physics blow-up?)"
    )


def outside(x: float, y: float, extent: float) -> str:
    """The fault message for a body beyond ``physics.extent``."""
    return f"body left the world at ({x:.4g}, {y:.4g}) m (physics.extent is {extent:g} m)"
