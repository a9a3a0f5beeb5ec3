"""A differential-drive rover: one pymunk rigid body driven by two wheel force points.

The wheels sit on the axle through the centre of mass at ±track/2 (body-frame y). Each
step the rover reads its body velocity, asks ``wheel.py`` for the wheel forces, and sets the
body's total force and torque; pymunk integrates them and resolves collisions. Nothing
teleports the body: sideways sliding is removed by a friction force, not by editing velocity.
"""

from __future__ import annotations

import math

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
        self.slipping = False

    def set_power(self, left_pct: float, right_pct: float) -> None:
        """Command the wheels; the motor driver saturates at ±100 %."""
        self.power_l = min(100.0, max(-100.0, left_pct))
        self.power_r = min(100.0, max(-100.0, right_pct))

    def apply_forces(self, dt: float) -> None:
        """Set this step's force and torque on the body from the wheel model."""
        body = self.body
        angle = body.angle
        c = math.cos(angle)
        s = math.sin(angle)
        vx, vy = body.velocity
        w = body.angular_velocity
        v_fwd = vx * c + vy * s
        v_lat = -vx * s + vy * c
        h = self.half_track
        wheel = self.wheel
        f_l = wheel.drive_force(self.power_l, v_fwd - w * h)
        f_r = wheel.drive_force(self.power_r, v_fwd + w * h)
        f_lat = lateral_force(v_lat, self.mass, dt, self.lateral_limit)
        fx = f_l + f_r
        body.force = (fx * c - f_lat * s, fx * s + f_lat * c)
        body.torque = (f_r - f_l) * h

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
