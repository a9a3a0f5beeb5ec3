"""IMU: a planar gyro and a two-axis accelerometer from the robot's published motion."""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ..engine import noise as nz
from ..model.params import Param
from ..model.sensorclock import stamped
from ..model.template import Kind, Port, Template


class _Optional(Port):
    """An input that may stay unlinked (the world's link check reads ``optional``)."""

    optional = True


class IMU(Template):
    """Gyro (yaw rate) and accelerometer (forward, lateral) with Gazebo noise and bias random walk.

    The accelerometer reports the specific force at the IMU's mounting point (``mountX``
    forward, ``mountY`` left of the centre of mass; the world is flat, so no gravity), in the
    body frame: ``a = dv_b/dt + w x v_b + alpha x r + w x (w x r)``, from finite differences
    over the IMU's own period (the average of the last period, half a period late; 0 until
    two samples exist). ``gyroZ = w``.

    With the robot's pose linked (``posX``, ``posY``, ``heading``) the body-frame velocity
    ``v_b`` includes the sideslip: it is the chord of the last period rotated into the body
    at the mid-period heading and divided by ``sinc(dtheta/2)``, which is exact for a steady
    turn or drift (a constant body-frame velocity), where ``a_x = -w v_y``: a skidding
    rover's sideways velocity shows up in the forward channel (ignoring it left
    the accelerometer 3.2 m/s² off in a skid). Without the pose (the 2019 wiring: ``speed``
    and ``yawRate`` only) the sideways velocity is taken as 0: ``a_x = dv/dt``, ``a_y = v w``.
    Each channel adds the SDFormat noise of ``engine/noise.py`` with the prefix ``gyro_`` or
    ``accel_`` (the accelerometer's two axes draw independently); a dynamic-bias correlation
    time of 0 (the default) makes the bias a random walk. Not modelled: gravity and tilt,
    vibration, scale-factor and misalignment errors, saturation. A lost sample
    (``lostData`` %) publishes nothing.
    """

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    kind = Kind.SENSOR
    inputs = (
        Port("speed", 0.0, "true forward speed", "m/s"),
        Port("yawRate", 0.0, "true yaw rate", "rad/s"),
        _Optional("posX", 0.0, "true position x (optional: with the pose, sideslip counts)", "m"),
        _Optional("posY", 0.0, "true position y (optional, with posX and heading)", "m"),
        _Optional("heading", 0.0, "true heading (optional, with posX and posY)", "rad"),
    )
    outputs = (
        Port("gyroZ", 0.0, "measured yaw rate", "rad/s"),
        Port("accelX", 0.0, "measured forward acceleration", "m/s²"),
        Port("accelY", 0.0, "measured lateral (centripetal) acceleration, left positive", "m/s²"),
    )
    params = (
        *nz.noise_params("gyro_", "rad/s", "yaw rate", 10.0),
        *nz.noise_params("accel_", "m/s²", "acceleration", 100.0),
        Param("lostData", "float", "share of samples lost", 0.0, 0.0, 100.0, "%"),
        Param("mountX", "float", "mounting point ahead of the centre of mass", 0.0, -5.0, 5.0, "m"),
        Param("mountY", "float", "mounting point left of the centre of mass", 0.0, -5.0, 5.0, "m"),
    )

    @classmethod
    def is_random(cls, values: Mapping[str, Any]) -> bool:
        """Noise, random biases or losses make the readings depend on the seed."""
        return (
            nz.is_noisy(values, "gyro_") or nz.is_noisy(values, "accel_") or values["lostData"] > 0
        )

    def initialize(self, ctx: Any) -> None:
        """Three streams split off this component's: gyro, accelerometer, losses."""
        gyro, accel, loss = ctx.rng.spawn(3)
        self.gyro = nz.Channel(gyro, 1, "gyro_")
        self.accel = nz.Channel(accel, 2, "accel_")
        self.loss = loss
        self.prev: tuple[float, ...] | None = None  # t, x, y, heading, yaw rate
        self.v_prev: tuple[float, float] | None = None  # body velocity, last period's

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: one gyro and accelerometer sample, or none if lost."""
        now = float(t)
        v, w = inp["speed"], inp["yawRate"]
        posed = "posX" in inp and "posY" in inp and "heading" in inp
        x, y, a = (inp["posX"], inp["posY"], inp["heading"]) if posed else (0.0, 0.0, 0.0)
        ax = ay = 0.0
        prev, v_prev = self.prev, self.v_prev
        vb: tuple[float, float] | None = None
        if prev is None:
            ay = 0.0 if posed else v * w
        elif posed:
            period = now - prev[0]
            vb = _body_velocity(x - prev[1], y - prev[2], prev[3], a, period)
            if v_prev is not None:
                ax = (vb[0] - v_prev[0]) / period - w * vb[1]
                ay = (vb[1] - v_prev[1]) / period + w * vb[0]
        else:  # the 2019 wiring: no sideways velocity
            period = now - prev[0]
            ax = (v - prev[5]) / period
            ay = v * w
        rx, ry = self.p.mountX, self.p.mountY
        if prev is not None and (rx or ry):  # the lever arm: alpha x r + w x (w x r)
            alpha = (w - prev[4]) / (now - prev[0])
            ax += -alpha * ry - w * w * rx
            ay += alpha * rx - w * w * ry
        self.prev = (now, x, y, a, w, v)
        self.v_prev = vb
        (gz,) = self.gyro.apply([w], now, self.p)
        mx, my = self.accel.apply([ax, ay], now, self.p)
        if float(self.loss.random()) * 100.0 < self.p.lostData:
            return {}
        return {"gyroZ": gz, "accelX": mx, "accelY": my}


def _body_velocity(
    dx: float, dy: float, a0: float, a1: float, period: float
) -> tuple[float, float]:
    """The body-frame velocity at mid-period from the chord ``(dx, dy)`` of a period in which
    the heading went from ``a0`` to ``a1``: exact for a constant body-frame velocity (a steady
    turn, drift or line), whose path is an arc: the chord points along the mid-period
    velocity and is shorter than the arc by ``sinc(dtheta / 2)``."""
    turn = math.remainder(a1 - a0, math.tau)
    half = 0.5 * turn
    k = math.sin(half) / half if half != 0.0 else 1.0
    mid = a0 + half
    c, s = math.cos(mid), math.sin(mid)
    return (dx * c + dy * s) / (period * k), (-dx * s + dy * c) / (period * k)


#: IMU with the sensor's own clock: an output ``stamp`` (``model/sensorclock.py``)
StampedIMU = stamped(IMU)
