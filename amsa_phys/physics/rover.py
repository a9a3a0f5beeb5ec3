"""A differential-drive rover: one pymunk rigid body driven by two wheel force points.

The wheels sit on the axle through the centre of mass at ±track/2 (body-frame y). Each
step ``forces.py`` (or ``fleet.py``, for many rovers) turns the body's velocity and the
commanded powers into the body's total force and torque; pymunk integrates them and resolves
collisions. Nothing teleports the body: sideways sliding is removed by a friction force, not
by editing velocity.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import pymunk

from .wheel import WheelModel


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
        self._source: Callable[[], Sequence[float]] | None = None

    def set_power(self, left_pct: float, right_pct: float) -> None:
        """Command the wheels; the motor driver saturates at ±100 %."""
        # chained comparisons, not min/max: this runs every control step of every rover
        self.power_l = left_pct if -100.0 <= left_pct <= 100.0 else _saturate(left_pct)
        self.power_r = right_pct if -100.0 <= right_pct <= 100.0 else _saturate(right_pct)
        if self._slot is not None:
            powers, i = self._slot
            powers[0, i] = self.power_l
            powers[1, i] = self.power_r

    def attach_power_slot(self, powers: Any, index: int) -> None:
        """Also write the commands into ``powers[:, index]`` (the batch path's arrays)."""
        self._slot = (powers, index)
        powers[0, index] = self.power_l
        powers[1, index] = self.power_r

    # -- state, read by the templates ----------------------------------------------------
    def attach_state(self, source: Callable[[], Sequence[float]]) -> None:
        """Read :meth:`kinematics` from ``source`` (the world's last batch read) from now on."""
        self._source = source

    def kinematics(self) -> Sequence[float]:
        """``x, y, angle, vx, vy, w`` now (the same floats pymunk holds).

        Served from the physics world's batch read of the last step when attached (reading
        pymunk properties one by one costs ~3 µs a rover, more than the rest of a sensor).
        """
        if self._source is not None:
            return self._source()
        body = self.body
        x, y = body.position
        vx, vy = body.velocity
        return x, y, body.angle, vx, vy, body.angular_velocity

    @property
    def pose(self) -> tuple[float, float, float]:
        """(x, y, heading) with heading wrapped to [-pi, pi)."""
        x, y, a = self.kinematics()[:3]
        return x, y, wrap_angle(a)

    @property
    def forward_speed(self) -> float:
        """Signed speed along the heading (m/s)."""
        _, _, a, vx, vy, _ = self.kinematics()
        return vx * math.cos(a) + vy * math.sin(a)

    def wheel_speeds(self) -> tuple[float, float]:
        """Ground speed of the left and right wheel contact points (m/s)."""
        _, _, a, vx, vy, w = self.kinematics()
        v = vx * math.cos(a) + vy * math.sin(a)
        return v - w * self.half_track, v + w * self.half_track


def _saturate(pct: float) -> float:
    """The motor driver's limit: ±100 % (NaN gives -100, as ``min(100, max(-100, nan))``)."""
    return min(100.0, max(-100.0, pct))


def wrap_angle(a: float) -> float:
    """Angle in [-pi, pi)."""
    return (a + math.pi) % (2 * math.pi) - math.pi
