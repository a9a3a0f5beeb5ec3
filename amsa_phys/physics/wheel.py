"""Forces at a driven wheel: motor, traction limit, rolling resistance, lateral grip.

Pure math, no pymunk, so the model can be checked by hand and in closed form:

* **Motor** (a voltage-controlled DC motor through a gearbox, as seen at the ground):
  ``F = F_stall * (eta * p/100 - v / v_free)``. Power ``p`` sets the voltage, so at constant
  power the wheel settles at a speed proportional to ``p`` (top speed ``eta * v_free`` at
  100 % before resistance), and back-EMF makes the force fall with speed. At 0 % the
  shorted motor brakes (``-F_stall * v / v_free``).
* **Traction**: the tyre transmits at most ``mu * N`` (friction times the wheel's normal
  load); asking for more makes the wheel slip and the force saturates at that limit.
* **Rolling resistance**: ``Crr * N`` against the motion, smoothed linearly below ``v_eps``
  so a rover at rest is not shaken by a sign that flips every step.
* **Lateral grip**: the force that cancels the wheel's sideways velocity within one step
  (an impulse, like pymunk's own contact friction), capped at ``mu_lat * N``: beyond it
  the rover skids.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class WheelModel:
    """One wheel's parameters, in SI units (forces per wheel)."""

    stall_force_n: float
    free_speed_mps: float
    efficiency: float
    traction_limit_n: float
    rolling_force_n: float
    v_eps_mps: float = 0.05

    def drive_force(self, power_pct: float, v_wheel: float) -> float:
        """Longitudinal ground force on the wheel (N) at ``power_pct`` and wheel speed."""
        motor = self.stall_force_n * (
            self.efficiency * power_pct * 0.01 - v_wheel / self.free_speed_mps
        )
        limit = self.traction_limit_n
        if motor > limit:
            motor = limit
        elif motor < -limit:
            motor = -limit
        ratio = v_wheel / self.v_eps_mps
        if ratio > 1.0:
            ratio = 1.0
        elif ratio < -1.0:
            ratio = -1.0
        return motor - self.rolling_force_n * ratio

    def is_slipping(self, power_pct: float, v_wheel: float) -> bool:
        """Whether the motor asks for more than the tyre can transmit."""
        motor = self.stall_force_n * (
            self.efficiency * power_pct * 0.01 - v_wheel / self.free_speed_mps
        )
        return abs(motor) > self.traction_limit_n

    def steady_speed(self, power_pct: float) -> float:
        """Closed-form top speed at constant ``power_pct`` on a straight line (m/s).

        Both wheels at ``v``: ``F_stall (eta p - v / v_free) = Crr N`` (above ``v_eps``).
        """
        drive = self.stall_force_n * self.efficiency * power_pct * 0.01
        if abs(drive) <= self.rolling_force_n:
            return 0.0
        sign = 1.0 if drive > 0 else -1.0
        return (drive - sign * self.rolling_force_n) * self.free_speed_mps / self.stall_force_n

    def power_for_speed(self, v_wheel: float) -> float:
        """Power (%) that holds a wheel at ``v_wheel`` against rolling resistance.

        The inverse of :meth:`steady_speed` per wheel: ``F_stall (eta p - v/v_free) = Crr N``.
        """
        if v_wheel == 0.0 or self.efficiency == 0.0:
            return 0.0
        sign = 1.0 if v_wheel > 0 else -1.0
        return (
            100.0
            * (v_wheel / self.free_speed_mps + sign * self.rolling_force_n / self.stall_force_n)
            / self.efficiency
        )


def lateral_force(v_lat: float, mass_kg: float, dt_s: float, limit_n: float) -> float:
    """Sideways force (N) that stops a sideways velocity in one step, capped by grip."""
    force = -mass_kg * v_lat / dt_s
    if force > limit_n:
        return limit_n
    if force < -limit_n:
        return -limit_n
    return force
