"""The two physical robot templates of the MDE challenge: ``freeRobot`` and ``controlledRobot``.

Both are differential-drive rovers in the run's pymunk world. ``controlledRobot`` (the
Follower, kind *process*) takes its wheel powers from Data; ``freeRobot`` (the Leader, kind
*environment*) drives itself by a behaviour (paper: "the leader may have different
behaviors"). At every step a robot publishes its true pose and applies the current power;
the physics advances between steps at ``physics.rate``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from ..model.params import Param
from ..model.template import Kind, ParamValues, Port, Template
from .rover import DiffDriveRover, wrap_angle
from .space import physics_of
from .wheel import scrub_moment

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
_WHEEL_PARAMS = {
    "stallForce",
    "freeSpeed",
    "efficiency",
    "maxWheelTorque",
    "deadband",
    "jointFriction",
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
_BODY_PARAMS = {
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

_POSE_OUTPUTS = (
    Port("posX", 0.0, "true x position", "m"),
    Port("posY", 0.0, "true y position", "m"),
    Port("heading", 0.0, "true heading in [-pi, pi)", "rad"),
    Port("speed", 0.0, "signed speed along the heading", "m/s"),
    Port("yawRate", 0.0, "angular velocity", "rad/s"),
    Port(
        "wheelSpeedL",
        0.0,
        "left wheel rim speed omega*r (what an encoder measures: includes tyre slip)",
        "m/s",
    ),
    Port(
        "wheelSpeedR",
        0.0,
        "right wheel rim speed omega*r (what an encoder measures: includes tyre slip)",
        "m/s",
    ),
)


class _Robot(Template):
    rover: DiffDriveRover
    fixed_once_running = frozenset(_BODY_PARAMS)
    #: a batch builds each run's rover from its parameters at t = 0 (the timeline may not
    #: change them during a batched run)
    batch_params_at_start = True

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """Refuse a geometry statics cannot stand on (``check_geometry``)."""
        check_geometry(values)

    def initialize(self, ctx: Any) -> None:
        self.physics = physics_of(ctx)
        self.rover = self.physics.add_rover(self.path, self.p)

    def on_param_change(self, name: str, value: Any) -> None:
        if name in _WHEEL_PARAMS:
            self.physics.update_wheel(self.rover, self.p)
        elif name in _BODY_PARAMS:
            raise ValueError(f"{name} is fixed once the run has started")

    def _pose(self) -> dict[str, float]:
        x, y, a, vx, vy, w = self.rover.kinematics()
        left, right = self.rover.wheel_speeds()
        return {
            "posX": x,
            "posY": y,
            "heading": wrap_angle(a),
            "speed": vx * math.cos(a) + vy * math.sin(a),
            "yawRate": w,
            "wheelSpeedL": left,
            "wheelSpeedR": right,
        }


class ControlledRobot(_Robot):
    """The controlled rover (the Follower): wheel powers in %, true pose out."""

    template_name = "controlledRobot"
    kind = Kind.PROCESS
    inputs = (
        Port("powerL", 0.0, "left wheel power", "%"),
        Port("powerR", 0.0, "right wheel power", "%"),
    )
    outputs = _POSE_OUTPUTS
    params = ROVER_PARAMS

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: apply the commanded powers, publish the pose."""
        self.rover.set_power(inp["powerL"], inp["powerR"])
        return self._pose()

    @classmethod
    def step_many(
        cls,
        comps: Sequence[ControlledRobot],
        t: Fraction,
        inp: Mapping[str, Any],
        p: Any,
        state: dict[str, Any],
    ) -> tuple[Mapping[str, Any], None]:
        """``do_step`` for many copies at once (``engine/batch.py``)."""
        physics = comps[0].physics
        if "index" not in state:
            state["index"] = physics.index_of([c.rover for c in comps])
        if "rovers" not in state:
            state["rovers"] = [c.rover for c in comps]
        physics.set_powers(state["rovers"], state["index"], inp["powerL"], inp["powerR"])
        x, y, a, vx, vy, w = physics.kinematics_array(state["index"]).T
        left, right = physics.rim_array(state["index"]).T
        return {
            "posX": x,
            "posY": y,
            "heading": (a + math.pi) % (2 * math.pi) - math.pi,
            "speed": vx * np.cos(a) + vy * np.sin(a),
            "yawRate": w,
            "wheelSpeedL": left,
            "wheelSpeedR": right,
        }, None


BEHAVIORS = {"straight": 1, "circle": 2, "speedChanges": 3, "random": 4, "waypoints": 5}


class FreeRobot(_Robot):
    """The free rover (the Leader): a physical rover driven by its own behaviour.

    Behaviours: 1 straight at ``cruisePower``; 2 a circle of ``circleRadius``; 3 straight with
    the power cycling through 100 %, 50 %, 150 %, 100 % of ``cruisePower`` every
    ``changePeriod`` s; 4 a random trajectory: every ``changePeriod`` s a new heading (within
    ±``randomTurn`` of the current one) and speed (50–120 % of cruise) drawn from the seed;
    5 ``waypoints`` in order, then stop. Headings are held by a proportional steering law
    (``steerGain`` % of differential power per radian, forward power times cos(error)). The
    circle's wheel powers come from the rover's own wheel model, so the radius is as asked.
    """

    template_name = "freeRobot"
    kind = Kind.ENVIRONMENT
    outputs = _POSE_OUTPUTS
    params = (
        Param(
            "behavior",
            "enum",
            "trajectory: 1 straight, 2 circle, 3 straight with speed "
            "changes, 4 random, 5 waypoints",
            1,
            choices=(1, 2, 3, 4, 5),
            aliases=BEHAVIORS,
        ),
        Param("cruisePower", "float", "wheel power when cruising", 22.0, -100.0, 100.0, "%"),
        Param(
            "circleRadius",
            "float",
            "radius of behaviour 2 (positive: counter-clockwise)",
            20.0,
            -1e4,
            1e4,
            "m",
        ),
        Param(
            "changePeriod",
            "float",
            "seconds between changes (behaviours 3 and 4)",
            30.0,
            0.5,
            1e5,
            "s",
        ),
        Param(
            "randomTurn", "float", "largest heading change of behaviour 4", 1.2, 0.0, math.pi, "rad"
        ),
        Param(
            "steerGain",
            "float",
            "differential power per radian of heading error",
            40.0,
            0.0,
            1000.0,
            "%/rad",
        ),
        Param("waypoints", "points", "[[x, y], ...] for behaviour 5", ()),
        Param(
            "waypointRadius",
            "float",
            "distance at which a waypoint counts as reached",
            1.0,
            0.01,
            1e4,
            "m",
        ),
        *ROVER_PARAMS,
    )

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """Refuse behaviour 5 without a waypoint: the leader would stand still all run,
        which looks like a physics bug rather than the missing list it is."""
        if values.get("behavior") == BEHAVIORS["waypoints"] and not values.get("waypoints"):
            raise ValueError("behavior 5 (waypoints) needs at least one point in waypoints")
        super().check_params(values)

    def initialize(self, ctx: Any) -> None:
        self.check_params(self.p.as_dict())
        super().initialize(ctx)
        self.rng = ctx.rng
        self.target_heading = self.p.heading
        self.speed_factor = 1.0
        self.next_change = Fraction(0)
        self.waypoint = 0

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: choose wheel powers by the behaviour, publish the pose."""
        left, right = self._behaviour(t)
        self.rover.set_power(left, right)
        return self._pose()

    @classmethod
    def step_many(
        cls,
        comps: Sequence[FreeRobot],
        t: Fraction,
        inp: Mapping[str, Any],
        p: Any,
        state: dict[str, Any],
    ) -> tuple[Mapping[str, Any], None]:
        """``do_step`` for many copies at once (a batched sweep's leaders): each copy's
        behaviour as alone, the powers and poses as arrays (``ControlledRobot.step_many``)."""
        straight = p.behavior == 1  # behaviour 1 is the cruise power on both wheels
        if straight.all():
            left = right = p.cruisePower
        else:
            powers = np.array(
                [
                    (cp, cp) if s else c._behaviour(t)
                    for c, s, cp in zip(
                        comps, straight.tolist(), p.cruisePower.tolist(), strict=True
                    )
                ],
                dtype=np.float64,
            )
            left, right = powers[:, 0], powers[:, 1]
        return ControlledRobot.step_many(
            comps,  # type: ignore[arg-type]
            t,
            {"powerL": left, "powerR": right},
            p,
            state,
        )

    def _behaviour(self, t: Fraction) -> tuple[float, float]:
        p = self.p
        cruise = p.cruisePower
        b = p.behavior
        if b == 2:
            # wheel speeds v (1 -+ h / r) for the cruise speed v, each converted back to the
            # power that holds it (so rolling resistance does not shrink the circle)
            return self._circle(cruise, p.circleRadius or 1e9)
        if b == 1:
            return cruise, cruise
        if t >= self.next_change:
            self.next_change = t + Fraction(str(p.changePeriod))
            if b == 3:
                cycle = (1.0, 0.5, 1.5, 1.0)
                self.speed_factor = cycle[int(t / Fraction(str(p.changePeriod))) % 4]
            elif b == 4:
                self.target_heading = self.rover.kinematics()[2] + self.rng.uniform(
                    -p.randomTurn, p.randomTurn
                )
                self.speed_factor = float(self.rng.uniform(0.5, 1.2))
        if b == 3:
            return cruise * self.speed_factor, cruise * self.speed_factor
        if b == 5:
            return self._waypoints(cruise)
        return self._steer(cruise * self.speed_factor, self.target_heading)

    def _circle(self, cruise: float, radius: float) -> tuple[float, float]:
        """Wheel powers for a circle of ``radius`` at the cruise speed, from the rover's own
        wheel model: hub speeds ``v (1 -+ h / r)``, each wheel also pushing against the
        tyres' scrub moment (so neither rolling resistance nor scrub widens the circle)."""
        wheel = self.rover.wheel
        terrain = self.physics.terrain
        crr, mu = terrain.rolling_resistance, terrain.friction
        h = self.rover.half_track
        v = wheel.steady_speed(cruise, crr)
        v_l, v_r = v * (1 - h / radius), v * (1 + h / radius)
        push = scrub_moment(v / radius, v_l, v_r, wheel, mu, mu) / (2 * h)
        return wheel.power_for_speed(v_l, crr, push), wheel.power_for_speed(v_r, crr, -push)

    def _steer(self, power: float, heading: float) -> tuple[float, float]:
        """Hold ``heading``: forward power falls with cos(error), so a large error turns the
        rover nearly in place instead of orbiting its target."""
        err = wrap_angle(heading - self.rover.kinematics()[2])
        diff = self.p.steerGain * err
        forward = power * max(0.0, math.cos(err))
        return forward - diff, forward + diff

    def _waypoints(self, cruise: float) -> tuple[float, float]:
        points = self.p.waypoints
        x, y = self.rover.kinematics()[:2]
        while self.waypoint < len(points):
            wx, wy = points[self.waypoint]
            if math.hypot(wx - x, wy - y) > self.p.waypointRadius:
                return self._steer(cruise, math.atan2(wy - y, wx - x))
            self.waypoint += 1
        return 0.0, 0.0
