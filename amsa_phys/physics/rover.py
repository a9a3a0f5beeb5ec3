"""A differential-drive rover: one pymunk rigid body driven by two wheel force points.

The wheels sit on the axle through the centre of mass at ±track/2 (body-frame y). Each
step the rover reads its body velocity, asks ``wheel.py`` for the wheel forces, and sets the
body's total force and torque; pymunk integrates them and resolves collisions. Nothing
teleports the body: sideways sliding is removed by a friction force, not by editing velocity.
"""

from __future__ import annotations

import math
from typing import Any

import pymunk

from .wheel import WheelModel, lateral_force


class DiffDriveRover:
    """A rover body in a pymunk space, commanded by left/right power in percent."""

    def __init__(
        self,
        space: pymunk.Space,
        name: str,
        *,
        mass_kg: float,
        length_m: float,
        width_m: float,
        track_m: float,
        wheel: WheelModel,
        lateral_limit_n: float,
        x: float,
        y: float,
        heading: float,
        collision_type: int,
    ) -> None:
        self.name = name
        self.mass = mass_kg
        self.length = length_m
        self.width = width_m
        self.half_track = track_m / 2
        self.wheel = wheel
        self.lateral_limit = lateral_limit_n  # both wheels together
        self.body = pymunk.Body(mass_kg, pymunk.moment_for_box(mass_kg, (length_m, width_m)))
        self.body.position = (x, y)
        self.body.angle = heading
        self.shape = pymunk.Poly.create_box(self.body, (length_m, width_m), radius=0.02)
        self.shape.friction = 0.6
        self.shape.elasticity = 0.1
        self.shape.collision_type = collision_type
        space.add(self.body, self.shape)
        self.power_l = 0.0
        self.power_r = 0.0
        self._slot: tuple[Any, int] | None = None
        self.slipping = False

    def set_power(self, left_pct: float, right_pct: float) -> None:
        """Command the wheels; the motor driver saturates at ±100 %."""
        self.power_l = min(100.0, max(-100.0, left_pct))
        self.power_r = min(100.0, max(-100.0, right_pct))
        if self._slot is not None:
            powers, i = self._slot
            powers[0, i] = self.power_l
            powers[1, i] = self.power_r

    def attach_power_slot(self, powers: Any, index: int) -> None:
        """Also write the commands into ``powers[:, index]`` (the batch path's arrays)."""
        self._slot = (powers, index)
        powers[0, index] = self.power_l
        powers[1, index] = self.power_r

    def apply_forces(self, dt: float) -> None:
        """Set this step's force and torque on the body from the wheel model.

        Lateral grip is a non-holonomic constraint: it must turn the velocity with the body
        without doing work. pymunk integrates velocity first, then the angle with the new
        angular velocity, so the heading at the end of the step is ``a + w' dt``. The grip
        impulse is applied along the normal at the *mid-step* heading and sized so the
        end-of-step velocity has no sideways component at the *end-of-step* heading: a pure
        rotation of the velocity (speed kept exactly). Cancelling sideways velocity at the
        start-of-step heading instead bleeds speed in every turn, by an amount that depends
        on the physics rate.
        """
        body = self.body
        angle = body.angle
        c = math.cos(angle)
        s = math.sin(angle)
        vx, vy = body.velocity
        w = body.angular_velocity
        v_fwd = vx * c + vy * s
        h = self.half_track
        wheel = self.wheel
        f_l = wheel.drive_force(self.power_l, v_fwd - w * h)
        f_r = wheel.drive_force(self.power_r, v_fwd + w * h)
        fx = f_l + f_r
        torque = (f_r - f_l) * h
        # predicted heading change over this step (semi-implicit Euler, as pymunk does)
        turn = (w + torque / body.moment * dt) * dt
        end = angle + turn
        mid = angle + 0.5 * turn
        nx_end, ny_end = -math.sin(end), math.cos(end)
        nx_mid, ny_mid = -math.sin(mid), math.cos(mid)
        # velocity after the drive force alone, and its sideways part at the end heading
        px = vx + fx * c / self.mass * dt
        py = vy + fx * s / self.mass * dt
        side = px * nx_end + py * ny_end
        f_lat = lateral_force(side / math.cos(0.5 * turn), self.mass, dt, self.lateral_limit)
        body.force = (fx * c + f_lat * nx_mid, fx * s + f_lat * ny_mid)
        body.torque = torque

    # -- state, read by the templates ----------------------------------------------------
    @property
    def pose(self) -> tuple[float, float, float]:
        """(x, y, heading) with heading wrapped to [-pi, pi)."""
        x, y = self.body.position
        return x, y, wrap_angle(self.body.angle)

    @property
    def forward_speed(self) -> float:
        """Signed speed along the heading (m/s)."""
        vx, vy = self.body.velocity
        a = self.body.angle
        return vx * math.cos(a) + vy * math.sin(a)

    def wheel_speeds(self) -> tuple[float, float]:
        """Ground speed of the left and right wheel contact points (m/s)."""
        v = self.forward_speed
        w = self.body.angular_velocity
        return v - w * self.half_track, v + w * self.half_track


def wrap_angle(a: float) -> float:
    """Angle in [-pi, pi)."""
    return (a + math.pi) % (2 * math.pi) - math.pi
