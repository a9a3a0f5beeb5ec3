"""A differential-drive rover: one pymunk rigid body driven by two wheels with spinning rims.

The wheels sit on the axle through the centre of mass at ±track/2 (body-frame y); a caster
(not modelled: frictionless) carries the rest. Each step ``fewrovers.py`` (or ``fleet.py``, for
many rovers) turns the body's velocity, the rims' spin and the commanded powers into the
body's total force and torque and the rims' new spin; pymunk integrates the body and resolves
collisions. Nothing teleports the body: sideways sliding is removed by a tyre force, not by
editing velocity.

The collision shape is a box with rounded corners whose *outer* extent is length × width, so
the rover drawn is the rover that touches.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import pymunk

from .wheel import WheelModel

#: Radius of the collision box's rounded corners (inside the rover's length × width).
CORNER_RADIUS_M = 0.02


class DiffDriveRover:
    """A rover body in a pymunk space, commanded by left/right power in percent."""

    def __init__(
        self,
        space: pymunk.Space | None,
        name: str,
        *,
        mass_kg: float,
        length_m: float,
        width_m: float,
        track_m: float,
        wheel: WheelModel,
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
        self.moment = pymunk.moment_for_box(mass_kg, (length_m, width_m))
        self.body = pymunk.Body(mass_kg, self.moment)
        self.body.position = (x, y)
        self.body.angle = heading
        rounding = min(CORNER_RADIUS_M, 0.25 * min(length_m, width_m))
        self.shape = pymunk.Poly.create_box(
            self.body, (length_m - 2 * rounding, width_m - 2 * rounding), radius=rounding
        )
        self.shape.friction = 0.6
        self.shape.elasticity = 0.1
        self.shape.collision_type = collision_type
        if space is not None:  # None: a batch's rover, whose columns move it (``space.py``)
            space.add(self.body, self.shape)
        # the commands behind the ``power_l`` ... ``drive_r`` properties
        self._power_l = 0.0
        self._power_r = 0.0
        self._drive_l = 0.0
        self._drive_r = 0.0
        #: the world's commands set for many rovers at once, not yet written here
        self._pending: PendingPowers = _NOTHING_PENDING
        self._slot_k = -1  # this rover's position in its pending commands
        self._slot: tuple[Any, int] | None = None
        self._source: Callable[[], Sequence[float]] | None = None
        self._rims: Callable[[], tuple[float, float]] | None = None

    # -- commands: the world may hold the newest (``PhysicsWorld.set_powers``) -------------
    @property
    def power_l(self) -> float:
        """Commanded left power (%), saturated at ±100 (what the renderer shows)."""
        if self._pending.dirty:
            self._pending.flush()
        return self._power_l

    @property
    def power_r(self) -> float:
        """Commanded right power (%), saturated at ±100."""
        if self._pending.dirty:
            self._pending.flush()
        return self._power_r

    @property
    def drive_l(self) -> float:
        """Left power the driver applies: 0 inside its deadband (what the force model reads)."""
        if self._pending.dirty:
            self._pending.flush()
        return self._drive_l

    @property
    def drive_r(self) -> float:
        """Right power the driver applies: 0 inside its deadband."""
        if self._pending.dirty:
            self._pending.flush()
        return self._drive_r

    def set_power(self, left_pct: float, right_pct: float) -> None:
        """Command the wheels; the motor driver saturates at ±100 % and has a deadband."""
        if self._pending.dirty:  # an older group command must not overwrite this one later
            self._pending.forget(self._slot_k)
        # chained comparisons, not min/max: this runs every control step of every rover
        self._power_l = left_pct if -100.0 <= left_pct <= 100.0 else _saturate(left_pct)
        self._power_r = right_pct if -100.0 <= right_pct <= 100.0 else _saturate(right_pct)
        self.update_drive()

    def update_drive(self) -> None:
        """Apply the driver's deadband to the commands (again after the deadband changed)."""
        if self._pending.dirty:
            self._pending.settle(self._slot_k)
        band = self.wheel.deadband_pct
        pl, pr = self._power_l, self._power_r
        self._drive_l = dl = pl if not -band < pl < band else 0.0
        self._drive_r = dr = pr if not -band < pr < band else 0.0
        if self._slot is not None:
            drives, i = self._slot
            drives[0, i] = dl
            drives[1, i] = dr

    def attach_power_slot(self, drives: Any, index: int) -> None:
        """Also write the applied powers into ``drives[:, index]`` (the batch path's arrays)."""
        self._slot = (drives, index)
        drives[0, index] = self.drive_l
        drives[1, index] = self.drive_r

    def attach_pending(self, pending: PendingPowers, k: int) -> None:
        """Read the commands through ``pending`` (its world's group commands, in which this
        rover is number ``k``) from now on."""
        if self._pending.dirty:
            self._pending.flush()
        self._pending = pending
        self._slot_k = k

    # -- state, read by the templates ----------------------------------------------------
    def attach_state(self, source: Callable[[], Sequence[float]]) -> None:
        """Read :meth:`kinematics` from ``source`` (the world's last batch read) from now on."""
        self._source = source

    def attach_rims(self, source: Callable[[], tuple[float, float]]) -> None:
        """Read :meth:`wheel_speeds` from ``source`` (the force model's rim state) from now on."""
        self._rims = source

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
        """Left and right rim speeds ``omega * r`` (m/s): what a wheel encoder measures.

        They differ from the ground speed of the hubs by the tyres' slip (a spinning wheel
        reads fast, a locked one zero). Before the first physics step: 0.
        """
        return self._rims() if self._rims is not None else (0.0, 0.0)


class PendingPowers:
    """A world's commands set for many rovers at once, written onto the rovers when read.

    Why: a platoon's grouped robots command 1,000 rovers at 4 Hz; setting four attributes on
    each rover in Python was ~18 % of the loop, while the force model reads the drives from
    its own (2, n) array. So :meth:`PhysicsWorld.set_powers` keeps the newest commands here
    as columns (``cmd``: power_l, power_r, drive_l, drive_r) and marks their rovers; a
    rover's ``power_l`` ... ``drive_r`` (the renderer, the pure force model, tests) and its
    ``set_power`` first :meth:`flush` them, so every reader sees the same floats as when
    each rover was set one by one, and a later single command still wins.
    """

    __slots__ = ("cmd", "dirty", "mask", "rovers")

    def __init__(self, rovers: list[DiffDriveRover]) -> None:
        self.rovers = rovers  # the world's list (it grows with add_rover)
        self.cmd: np.ndarray | None = None
        self.mask: np.ndarray | None = None
        self.dirty = False

    def put(
        self,
        index: np.ndarray,
        power_l: np.ndarray,
        power_r: np.ndarray,
        drive_l: np.ndarray,
        drive_r: np.ndarray,
    ) -> None:
        """The newest commands of the rovers at ``index`` (positions in ``rovers``)."""
        n = len(self.rovers)
        if self.cmd is None or self.cmd.shape[1] != n:
            if self.dirty:
                self.flush()
            self.cmd = np.zeros((4, n))
            self.mask = np.zeros(n, dtype=bool)
        cmd = self.cmd
        cmd[0, index] = power_l
        cmd[1, index] = power_r
        cmd[2, index] = drive_l
        cmd[3, index] = drive_r
        self.mask[index] = True  # type: ignore[index]
        self.dirty = True

    def forget(self, k: int) -> None:
        """Drop rover ``k``'s pending command (a newer one is being set on the rover)."""
        if self.mask is not None and k < len(self.mask):
            self.mask[k] = False

    def settle(self, k: int) -> None:
        """Write rover ``k``'s pending command onto it (the others stay pending)."""
        mask = self.mask
        if mask is not None and self.cmd is not None and k < len(mask) and mask[k]:
            mask[k] = False
            pl, pr, dl, dr = self.cmd[:, k].tolist()
            rover = self.rovers[k]
            rover._power_l = pl
            rover._power_r = pr
            rover._drive_l = dl
            rover._drive_r = dr

    def flush(self) -> None:
        """Write the pending commands onto their rovers."""
        self.dirty = False
        if self.cmd is None or self.mask is None:
            return
        where = np.flatnonzero(self.mask)
        self.mask[where] = False
        rovers = self.rovers
        for k, pl, pr, dl, dr in zip(where.tolist(), *self.cmd[:, where].tolist(), strict=True):
            rover = rovers[k]
            rover._power_l = pl
            rover._power_r = pr
            rover._drive_l = dl
            rover._drive_r = dr


#: the commands of a rover outside any world's group (never dirty)
_NOTHING_PENDING = PendingPowers([])


def _saturate(pct: float) -> float:
    """The motor driver's limit: ±100 % (NaN gives -100, as ``min(100, max(-100, nan))``)."""
    return min(100.0, max(-100.0, pct))


def wrap_angle(a: float) -> float:
    """Angle in [-pi, pi)."""
    return (a + math.pi) % (2 * math.pi) - math.pi
