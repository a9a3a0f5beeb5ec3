"""IMU: a planar gyro and a two-axis accelerometer built from the robot's speed and yaw rate."""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ..engine import noise as nz
from ..model.params import Param
from ..model.template import Kind, Port, Template


class IMU(Template):
    """Gyro (yaw rate) and accelerometer (forward, lateral) with Gazebo noise and bias random walk.

    Built from the robot's ``speed`` v and ``yawRate`` ω, the only motion Data a robot
    publishes: ``gyroZ = ω``; ``accelX`` = (v − v_prev) / Δt, the finite difference of the
    speed over the IMU's own period (so the forward acceleration averaged over the last
    period, half a period late; 0 at the first sample); ``accelY = v ω``, the centripetal
    acceleration. Each channel adds the SDFormat noise of ``sensors/noise.py`` with the
    prefix ``gyro_`` or ``accel_`` (the accelerometer's two axes draw independently); a
    dynamic-bias correlation time of 0 (the default) makes the bias a random walk, the usual
    model of an IMU's bias instability. Not modelled: gravity and tilt (the world is a
    plane), the lever arm (the IMU sits at the centre of mass), lateral slip acceleration
    (a robot publishes no sideways speed), vibration, scale-factor and misalignment errors,
    saturation. A lost sample (``lostData`` %) publishes nothing.
    """

    kind = Kind.SENSOR
    inputs = (
        Port("speed", 0.0, "true forward speed", "m/s"),
        Port("yawRate", 0.0, "true yaw rate", "rad/s"),
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
        self.v_prev: float | None = None
        self.t_prev = 0.0

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: one gyro and accelerometer sample, or none if lost."""
        now = float(t)
        v, w = inp["speed"], inp["yawRate"]
        ax = 0.0 if self.v_prev is None else (v - self.v_prev) / (now - self.t_prev)
        self.v_prev, self.t_prev = v, now
        (gz,) = self.gyro.apply([w], now, self.p)
        mx, my = self.accel.apply([ax, v * w], now, self.p)
        if float(self.loss.random()) * 100.0 < self.p.lostData:
            return {}
        return {"gyroZ": gz, "accelX": mx, "accelY": my}
