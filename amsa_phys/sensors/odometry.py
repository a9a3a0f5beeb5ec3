"""WheelOdometry: dead reckoning from the two wheel encoders of a differential-drive rover."""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ..engine import noise as nz
from ..model.params import Param
from ..model.sensorclock import stamped
from ..model.template import Kind, Port, Template


class WheelOdometry(Template):
    """Pose by dead reckoning from the wheel encoders: exact without slip, drifting with it.

    Reads ``wheelSpeedL``/``wheelSpeedR``, what the robot's encoders report (the rim speed
    of each wheel, so a spinning or locked wheel misleads the odometry as it would a real
    one). Each reading is scaled by (1 + ``scaleErrorL``/``scaleErrorR`` %) — a wheel radius
    off by that much, the main source of systematic drift — and gets the SDFormat noise of
    ``sensors/noise.py`` (per wheel, in m/s; ``precision`` is the speed resolution: an
    encoder of tick length d read every T seconds resolves d/T). Between two samples each
    wheel travels the mean of its two readings times Δt (trapezoid), and the pose moves
    along the exact arc those distances describe (chord ``ds·sin(dθ/2)/(dθ/2)`` at the mid
    heading), so constant wheel speeds — a straight line or a circle — are integrated
    without error. The odometry frame starts at (``x``, ``y``, ``heading``): set them to the
    robot's initial pose to compare with the truth. Run it at the robot's rate: it sees the
    wheel speeds only when the robot publishes them. A lost sample (``lostData`` %)
    publishes nothing, but the integration goes on (encoder counts are cumulative).
    """

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    kind = Kind.SENSOR
    inputs = (
        Port("wheelSpeedL", 0.0, "left wheel rim speed (encoder)", "m/s"),
        Port("wheelSpeedR", 0.0, "right wheel rim speed (encoder)", "m/s"),
    )
    outputs = (
        Port("odomX", 0.0, "dead-reckoned x", "m"),
        Port("odomY", 0.0, "dead-reckoned y", "m"),
        Port("odomHeading", 0.0, "dead-reckoned heading in [-pi, pi)", "rad"),
    )
    params = (
        Param("track", "float", "wheel separation assumed by the odometry", 0.5, 0.02, 20.0, "m"),
        Param("x", "float", "initial x of the odometry frame", 0.0, -1e5, 1e5, "m"),
        Param("y", "float", "initial y of the odometry frame", 0.0, -1e5, 1e5, "m"),
        Param(
            "heading",
            "float",
            "initial heading of the odometry frame",
            0.0,
            -2 * math.pi,
            2 * math.pi,
            "rad",
        ),
        Param("scaleErrorL", "float", "left wheel radius error", 0.0, -50.0, 50.0, "%"),
        Param("scaleErrorR", "float", "right wheel radius error", 0.0, -50.0, 50.0, "%"),
        *nz.noise_params("", "m/s", "wheel speed", 10.0),
        Param("lostData", "float", "share of samples lost", 0.0, 0.0, 100.0, "%"),
    )
    fixed_once_running = frozenset({"x", "y", "heading"})

    @classmethod
    def is_random(cls, values: Mapping[str, Any]) -> bool:
        """Noise, random biases or losses make the pose depend on the seed."""
        return nz.is_noisy(values) or values["lostData"] > 0

    def initialize(self, ctx: Any) -> None:
        """The pose starts at the parameters; two streams: encoder noise, losses."""
        enc, loss = ctx.rng.spawn(2)
        self.enc = nz.Channel(enc, 2)
        self.loss = loss
        self.x, self.y, self.heading = self.p.x, self.p.y, self.p.heading
        self.prev: tuple[float, float, float] | None = None  # t, left, right

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: integrate the wheel travel since the last sample."""
        now = float(t)
        p = self.p
        left = inp["wheelSpeedL"] * (1.0 + p.scaleErrorL / 100.0)
        right = inp["wheelSpeedR"] * (1.0 + p.scaleErrorR / 100.0)
        left, right = self.enc.apply([left, right], now, p)
        if self.prev is not None:
            t0, l0, r0 = self.prev
            dt = now - t0
            self.advance(0.5 * (l0 + left) * dt, 0.5 * (r0 + right) * dt, p.track)
        self.prev = (now, left, right)
        if float(self.loss.random()) * 100.0 < p.lostData:
            return {}
        heading = (self.heading + math.pi) % (2 * math.pi) - math.pi
        return {"odomX": self.x, "odomY": self.y, "odomHeading": heading}

    def advance(self, dl: float, dr: float, track: float) -> None:
        """Move the pose along the arc on which the wheels travel ``dl`` and ``dr``."""
        ds = 0.5 * (dl + dr)
        dth = (dr - dl) / track
        half = 0.5 * dth
        chord = ds * (math.sin(half) / half if half != 0.0 else 1.0)
        mid = self.heading + half
        self.x += chord * math.cos(mid)
        self.y += chord * math.sin(mid)
        self.heading += dth


#: WheelOdometry with the sensor's own clock: an output ``stamp`` (``model/sensorclock.py``)
StampedWheelOdometry = stamped(WheelOdometry)
