"""A rover's power supply: a battery whose terminal voltage sets what the motors get, and the
motors' winding temperature, which derates them when hot.

Why here and not in the physics step: both change over minutes, far slower than the step's
tyre and rim modes, so the robot updates them once a control step from the currents of the
state it publishes, and passes their effect on as the driver's duty: a voltage-controlled
driver at duty p on a supply V gives the motor p V / V_motor of the voltage its parameters
(``stallForce``, ``freeSpeed``) are stated at, which is the commanded power scaled by
``V / V_motor`` (the back-EMF, a property of the motor, is unchanged). The physics step, its
C twin and the paper's worlds (no battery: ``batteryCapacity`` 0) are untouched.

Model, per control step of length dt, currents taken from the step's start (one step of lag,
documented; the control period is far below every time constant here):

* motor current ``I_i = I_stall F_i / F_stall``, ``F_i`` the motor's force at the ground
  (current-limited), ``I_stall`` its stall current at ``V_motor``;
* battery current ``I_b = max(0, I_load + sum_i d_i I_i)`` (a PWM driver draws its duty ``d_i``
  of the motor current; no regeneration; ``I_load`` the rest of the rover);
* charge ``q -= I_b dt / (3600 Q)`` (capacity Q in A h), open-circuit voltage linear in the
  charge between ``batteryEmptyVoltage`` and ``batteryFullVoltage``, terminal voltage
  ``V = OCV(q) - I_b R``;
* winding temperature: first order towards ``T_amb + rise (I_i / I_stall)^2`` with time constant
  ``tau`` (``C dT/dt = I^2 R_w - (T - T_amb) / R_th``: ``tau = R_th C``, ``rise = I_stall^2 R_w
  R_th``), stepped exactly for the step's constant current; above ``motorTempLimit`` the
  driver derates linearly to nothing at ``motorTempMax``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..model.params import Param

#: The supply's parameters (``controlledRobot``): off unless ``batteryCapacity`` > 0 or
#: ``motorThermalTau`` > 0. Defaults: a 6-cell lithium-ion pack (4.2 V to 3.3 V a cell, about
#: 8 mOhm a cell with wiring) on motors stated at the full pack's voltage (a full pack gives
#: the stated top speed less its IR drop; the driver cannot command more than the supply),
#: a small geared motor's winding (tens of seconds
#: to minutes of thermal time constant, class-B insulation's 130 °C less margin).
POWER_PARAMS: tuple[Param, ...] = (
    Param(
        "batteryCapacity", "float", "battery capacity (0: an ideal supply)", 0.0, 0.0, 1e4, "A h"
    ),
    Param("batteryCharge", "float", "battery charge at the start", 100.0, 0.0, 100.0, "%"),
    Param("batteryFullVoltage", "float", "open-circuit voltage when full", 25.2, 0.1, 1e4, "V"),
    Param("batteryEmptyVoltage", "float", "open-circuit voltage when empty", 19.8, 0.0, 1e4, "V"),
    Param(
        "batteryLoad",
        "float",
        "the rest of the rover's constant draw (computer, sensors)",
        0.0,
        0.0,
        1e4,
        "A",
    ),
    Param("batteryResistance", "float", "battery internal resistance", 0.05, 0.0, 100.0, "ohm"),
    Param(
        "motorVoltage",
        "float",
        "supply voltage at which stallForce and freeSpeed are stated (the driver's duty never "
        "exceeds 100 %: keep it at or above the full pack's voltage)",
        25.2,
        0.1,
        1e4,
        "V",
    ),
    Param(
        "stallCurrent",
        "float",
        "one motor's current at stall and motorVoltage",
        10.0,
        0.0,
        1e4,
        "A",
    ),
    Param(
        "motorThermalTau",
        "float",
        "winding thermal time constant (0: no heating model)",
        0.0,
        0.0,
        1e6,
        "s",
    ),
    Param(
        "motorStallRise",
        "float",
        "steady winding temperature rise at the stall current",
        100.0,
        0.0,
        1e4,
        "K",
    ),
    Param(
        "ambientTemp",
        "float",
        "ambient and starting winding temperature",
        25.0,
        -100.0,
        200.0,
        "degC",
    ),
    Param(
        "motorTempLimit",
        "float",
        "winding temperature where derating starts",
        80.0,
        -100.0,
        1e3,
        "degC",
    ),
    Param("motorTempMax", "float", "winding temperature of no output", 120.0, -100.0, 1e3, "degC"),
)

POWER_NAMES = frozenset(p.name for p in POWER_PARAMS)


@dataclass
class Battery:
    """Charge (0-1) and terminal voltage of a battery of ``capacity_ah``."""

    capacity_ah: float
    charge: float
    full_v: float
    empty_v: float
    resistance: float
    current: float = 0.0

    def ocv(self) -> float:
        """Open-circuit voltage, linear in the charge."""
        return self.empty_v + (self.full_v - self.empty_v) * self.charge

    def voltage(self) -> float:
        """Terminal voltage at the last current: ``OCV - I R`` (never below 0)."""
        return max(0.0, self.ocv() - self.current * self.resistance)

    def draw(self, current: float, dt: float) -> None:
        """Draw ``current`` (A) for ``dt`` (s): charge falls by ``I dt / (3600 Q)``, never
        below empty."""
        self.current = current
        self.charge = max(0.0, self.charge - current * dt / (3600.0 * self.capacity_ah))


@dataclass
class Winding:
    """A motor winding's temperature: first order towards ``ambient + rise (I / I_stall)^2``."""

    tau: float
    rise: float
    ambient: float
    temp: float

    def heat(self, current_ratio: float, dt: float) -> None:
        """Step ``dt`` at the constant current ``I / I_stall``: exact for a first-order lag."""
        target = self.ambient + self.rise * current_ratio * current_ratio
        self.temp = target + (self.temp - target) * math.exp(-dt / self.tau)


def derating(temp: float, limit: float, top: float) -> float:
    """The driver's output share at winding temperature ``temp``: 1 up to ``limit``, falling
    linearly to 0 at ``top``."""
    if temp <= limit:
        return 1.0
    if temp >= top or top <= limit:
        return 0.0
    return (top - temp) / (top - limit)


class PowerSupply:
    """The battery and both windings of one rover, and the duty scale they leave the driver."""

    def __init__(self, p: Any) -> None:
        def g(name: str) -> float:
            return float(getattr(p, name))

        self.battery = (
            Battery(
                g("batteryCapacity"),
                g("batteryCharge") / 100.0,
                g("batteryFullVoltage"),
                g("batteryEmptyVoltage"),
                g("batteryResistance"),
            )
            if g("batteryCapacity") > 0.0
            else None
        )
        tau = g("motorThermalTau")
        self.windings = (
            [Winding(tau, g("motorStallRise"), g("ambientTemp"), g("ambientTemp")) for _ in "LR"]
            if tau > 0.0
            else None
        )
        self.motor_v = g("motorVoltage")
        self.stall_current = g("stallCurrent")
        self.limit, self.top = g("motorTempLimit"), g("motorTempMax")
        self.load = g("batteryLoad")
        self.scale = (self.supply_ratio(), self.supply_ratio())

    def supply_ratio(self) -> float:
        """``V / V_motor`` (1 with an ideal supply)."""
        return self.battery.voltage() / self.motor_v if self.battery is not None else 1.0

    def update(
        self, forces: tuple[float, float], duties: tuple[float, float], stall: float, dt: float
    ) -> None:
        """Advance by ``dt`` with the motors' forces at the ground (N) and duties (0-1) of
        the step that ends, ``stall`` the stall force; sets :attr:`scale`."""
        ratios = [f / stall if stall > 0.0 else 0.0 for f in forces]
        if self.battery is not None:
            drawn = self.load + sum(
                d * r * self.stall_current for d, r in zip(duties, ratios, strict=True)
            )
            self.battery.draw(max(0.0, drawn), dt)
        v = self.supply_ratio()
        if self.windings is None:
            self.scale = (v, v)
            return
        for w, r in zip(self.windings, ratios, strict=True):
            w.heat(r, dt)
        self.scale = tuple(v * derating(w.temp, self.limit, self.top) for w in self.windings)  # type: ignore[assignment]


def power_on(p: Any) -> bool:
    """Whether ``p`` (a robot's parameters) asks for a battery or a winding model."""
    return float(p.batteryCapacity) > 0.0 or float(p.motorThermalTau) > 0.0
