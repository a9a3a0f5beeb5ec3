"""A rover's physical parameters: what each means, its default and range, which may change.

Shared by both robot templates (``robots.py``, ``freerobot.py``) and read by the physics
world when it builds a rover (``space.py``); tests and benchmarks build rovers from
:func:`rover_params`. Split from ``templates.py``: the table is data, the
templates are behaviour.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from ..model.params import Param
from ..model.template import ParamValues

#: Physical parameters shared by both robots. The defaults describe a 30 kg two-wheel
#: differential-drive base on casters, in the class of the AgileX Tracer or a MiR100-type
#: indoor/outdoor carrier: 1.53 m/s top speed at 100 % on the default ground, 0.21 s motor
#: time constant, launches at 2.2 m/s^2 (the driver's current limit, well under the tyres'
#: grip on dry ground), starts moving from 4.1 % of power. Names follow Gazebo/SDFormat where
#: one exists (wheel_radius, max_wheel_torque, joint friction, WheelSlip compliances,
#: torsional patch_radius), in this project's camelCase.
ROVER_PARAMS: tuple[Param, ...] = (
    Param("x", "float", "initial x position", 0.0, -1e5, 1e5, "m"),
    Param("y", "float", "initial y position", 0.0, -1e5, 1e5, "m"),
    Param(
        "heading",
        "float",
        "initial heading (0 = +x, counter-clockwise)",
        0.0,
        -2 * math.pi,
        2 * math.pi,
        "rad",
    ),
    Param("mass", "float", "total mass", 30.0, 0.1, 10000.0, "kg"),
    Param("length", "float", "chassis length (along the heading)", 0.8, 0.05, 20.0, "m"),
    Param("width", "float", "chassis width", 0.6, 0.05, 20.0, "m"),
    Param("track", "float", "distance between the two driven wheels", 0.5, 0.02, 20.0, "m"),
    Param("wheelRadius", "float", "driven wheel radius (Gazebo wheel_radius)", 0.1, 0.01, 5.0, "m"),
    Param(
        "wheelInertia",
        "float",
        "one driven wheel's moment of inertia about its axle, motor rotor included "
        "(reflected through the gearbox)",
        0.01,
        1e-5,
        1000.0,
        "kg m^2",
    ),
    Param(
        "stallForce",
        "float",
        "motor force per wheel at the ground at 100 % and standstill, before the current limit",
        120.0,
        0.1,
        1e5,
        "N",
    ),
    Param(
        "freeSpeed",
        "float",
        "rim speed at which the motor force vanishes at 100 % (no-load speed)",
        1.6,
        0.01,
        100.0,
        "m/s",
    ),
    Param(
        "efficiency",
        "float",
        "motor efficiency: share of the commanded voltage delivered",
        100.0,
        0.0,
        100.0,
        "%",
    ),
    Param(
        "maxWheelTorque",
        "float",
        "driver current limit as wheel torque, driving and braking (Gazebo max_wheel_torque)",
        4.0,
        0.001,
        1e5,
        "N m",
    ),
    Param(
        "deadband",
        "float",
        "driver deadband: commands of smaller magnitude apply no voltage",
        2.0,
        0.0,
        50.0,
        "%",
    ),
    Param(
        "jointFriction",
        "float",
        "Coulomb friction of the wheel's axle and gearbox (SDFormat joint dynamics friction)",
        0.2,
        0.0,
        1e4,
        "N m",
    ),
    Param(
        "slipComplianceLongitudinal",
        "float",
        "tyre slip ratio per unit of longitudinal force / normal load (Gazebo WheelSlip); "
        "the force saturates at slip ratio friction x this",
        0.1,
        1e-4,
        10.0,
    ),
    Param(
        "slipComplianceLateral",
        "float",
        "tyre lateral slip (tan of the slip angle) per unit of lateral force / normal load "
        "(Gazebo WheelSlip)",
        0.1,
        1e-4,
        10.0,
    ),
    Param(
        "patchRadius",
        "float",
        "tyre contact patch radius: sets the scrub torque resisting a turn in place "
        "(SDFormat torsional patch_radius)",
        0.03,
        0.0,
        1.0,
        "m",
    ),
    Param(
        "tractionCoef",
        "float",
        "tyre grip along the wheel, times the ground friction",
        1.0,
        0.0,
        5.0,
    ),
    Param(
        "lateralCoef",
        "float",
        "tyre grip across the wheel, times the ground friction",
        1.0,
        0.0,
        5.0,
    ),
    Param("rollingCoef", "float", "rolling resistance, times the ground's", 1.0, 0.0, 20.0),
    Param(
        "brakeTorque",
        "float",
        "holding brake per driven wheel, engaged while the driver applies no voltage (the "
        "command within the deadband): a parked rover holds on slopes it can climb",
        0.0,
        0.0,
        1e5,
        "N m",
    ),
    Param(
        "axleOffset",
        "float",
        "drive axle's position ahead of the centre of mass (negative: behind); with "
        "casterOffset it shares the weight between the drive wheels and the caster by statics",
        0.05,
        -10.0,
        10.0,
        "m",
    ),
    Param(
        "casterOffset",
        "float",
        "caster's contact point ahead of the centre of mass (negative: behind); on the other "
        "side of the centre of mass from the axle",
        -0.3,
        -10.0,
        10.0,
        "m",
    ),
    Param(
        "comHeight",
        "float",
        "centre of mass's height above the ground: drive and braking forces move load between "
        "the drive wheels and the caster (load transfer)",
        0.2,
        0.0,
        10.0,
        "m",
    ),
)


def check_geometry(values: Mapping[str, Any]) -> None:
    """Refuse a drive axle and caster that cannot carry the body: statics needs the centre
    of mass between them (or over the axle), else one of them would pull the ground."""
    axle = values.get("axleOffset", 0.05)
    caster = values.get("casterOffset", -0.3)
    if caster == 0.0 or axle * caster > 0.0:
        raise ValueError(
            f"casterOffset {caster:g} m and axleOffset {axle:g} m must lie on opposite sides "
            "of the centre of mass (the caster not on it)"
        )


def rover_params(**overrides: Any) -> ParamValues:
    """The rover parameters' defaults with ``overrides`` (for tests and benchmarks)."""
    values = {q.name: q.default for q in ROVER_PARAMS}
    unknown = set(overrides) - set(values)
    if unknown:
        raise KeyError(f"not rover parameters: {sorted(unknown)}")
    return ParamValues(values | overrides)


#: Parameters that change the wheel model mid-run (motor wear, tyres, driver settings).
WHEEL_PARAMS = {
    "stallForce",
    "freeSpeed",
    "efficiency",
    "maxWheelTorque",
    "deadband",
    "jointFriction",
    "brakeTorque",
    "slipComplianceLongitudinal",
    "slipComplianceLateral",
    "patchRadius",
    "tractionCoef",
    "lateralCoef",
    "rollingCoef",
    "axleOffset",
    "casterOffset",
    "comHeight",
}
#: Parameters fixed once the body exists.
BODY_PARAMS = {
    "x",
    "y",
    "heading",
    "mass",
    "length",
    "width",
    "track",
    "wheelRadius",
    "wheelInertia",
}
