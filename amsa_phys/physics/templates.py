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
from ..model.template import Kind, Port, Template
from .rover import DiffDriveRover, wrap_angle
from .space import physics_of

#: Physical parameters shared by both robots. Defaults: a 30 kg outdoor rover, about 5.1 m/s
#: top speed at 100 % on the default ground, motor time constant
#: m * freeSpeed / (2 * stallForce) = 1.8 s.
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
    Param(
        "stallForce", "float", "motor force per wheel at 100 % and standstill", 45.0, 0.1, 1e5, "N"
    ),
    Param(
        "freeSpeed",
        "float",
        "wheel speed at which the motor force vanishes at 100 %",
        5.5,
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
)

#: Parameters that change the wheel model mid-run (motor wear, terrain).
_WHEEL_PARAMS = {
    "stallForce",
    "freeSpeed",
    "efficiency",
    "tractionCoef",
    "lateralCoef",
    "rollingCoef",
}
#: Parameters fixed once the body exists.
_BODY_PARAMS = {"x", "y", "heading", "mass", "length", "width", "track"}

_POSE_OUTPUTS = (
    Port("posX", 0.0, "true x position", "m"),
    Port("posY", 0.0, "true y position", "m"),
    Port("heading", 0.0, "true heading in [-pi, pi)", "rad"),
    Port("speed", 0.0, "signed speed along the heading", "m/s"),
    Port("yawRate", 0.0, "angular velocity", "rad/s"),
    Port("wheelSpeedL", 0.0, "left wheel ground speed (what an encoder measures)", "m/s"),
    Port("wheelSpeedR", 0.0, "right wheel ground speed (what an encoder measures)", "m/s"),
)


class _Robot(Template):
    rover: DiffDriveRover
    fixed_once_running = frozenset(_BODY_PARAMS)

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
        v = vx * math.cos(a) + vy * math.sin(a)
        h = self.rover.half_track
        return {
            "posX": x,
            "posY": y,
            "heading": wrap_angle(a),
            "speed": v,
            "yawRate": w,
            "wheelSpeedL": v - w * h,
            "wheelSpeedR": v + w * h,
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
            state["half_track"] = np.array([c.rover.half_track for c in comps])
        if "rovers" not in state:
            state["rovers"] = [c.rover for c in comps]
        physics.set_powers(state["rovers"], state["index"], inp["powerL"], inp["powerR"])
        x, y, a, vx, vy, w = physics.kinematics_array(state["index"]).T
        v = vx * np.cos(a) + vy * np.sin(a)
        wh = w * state["half_track"]
        return {
            "posX": x,
            "posY": y,
            "heading": (a + math.pi) % (2 * math.pi) - math.pi,
            "speed": v,
            "yawRate": w,
            "wheelSpeedL": v - wh,
            "wheelSpeedR": v + wh,
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

    def initialize(self, ctx: Any) -> None:
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

    def _behaviour(self, t: Fraction) -> tuple[float, float]:
        p = self.p
        cruise = p.cruisePower
        b = p.behavior
        if b == 2:
            # wheel speeds v (1 -+ h / r) for the cruise speed v, each converted back to the
            # power that holds it (so rolling resistance does not shrink the circle)
            wheel = self.rover.wheel
            v = wheel.steady_speed(cruise)
            k = self.rover.half_track / (p.circleRadius or 1e9)
            return wheel.power_for_speed(v * (1 - k)), wheel.power_for_speed(v * (1 + k))
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
