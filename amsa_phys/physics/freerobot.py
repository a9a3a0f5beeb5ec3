"""``freeRobot``: the rover that drives itself (the Leader) by one of five behaviours.

Kind *environment*: it reads no Data; the paper's "the leader may have different behaviors"
are its ``behavior`` parameter (straight, circle, speed changes, random, waypoints). Its body,
parameters and pose are the robots' common base (``robots.Robot``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from ..engine.batch import derived
from ..engine.clock import at_or_after
from ..model.params import Param
from ..model.template import Kind
from .robots import POSE_NAMES, POSE_OUTPUTS, ControlledRobot, Robot, pose_arrays
from .roverparams import ROVER_PARAMS
from .scrub import scrub_moment

_PI, _TWO_PI, _cos = math.pi, 2 * math.pi, math.cos

BEHAVIORS = {"straight": 1, "circle": 2, "speedChanges": 3, "random": 4, "waypoints": 5}


class FreeRobot(Robot):
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
    outputs = POSE_OUTPUTS
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
    def is_random(cls, values: Mapping[str, Any]) -> bool:
        """Only behaviour 4 (random) draws from the seed (``sweep`` asks, for its grid)."""
        return values.get("behavior") == BEHAVIORS["random"]

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
        plan = derived(state, "_behaviours", (p.behavior,), _behaviours)
        if plan is None:  # every copy cruises straight (behaviour 1)
            left = right = p.cruisePower
        else:
            others, rows = plan
            if len(others) == 0 and rows is not None and len(rows) == len(comps):
                # every copy random: its powers are the steering's arrays themselves (what
                # filling copies of the cruise power row by row would give)
                mine = cls._random_draws(comps, t, p, rows, state)
                poses = _leader_step(comps, p, rows, state, mine)
                if poses is not None:  # steering, powers and poses in one C call
                    return poses, None
                left, right = cls._steer_many(p, rows, state, mine)
            else:
                left = np.array(p.cruisePower, dtype=np.float64)
                right = left.copy()
                for i in others:  # circles, waypoints, ...
                    left[i], right[i] = comps[i]._behaviour(t)
                if rows is not None:
                    sl, sr = cls._random_many(comps, t, p, rows, state)
                    left[rows], right[rows] = sl, sr
        return ControlledRobot.step_many(
            comps,  # type: ignore[arg-type]
            t,
            {"powerL": left, "powerR": right},
            p,
            state,
        )

    @classmethod
    def _random_many(
        cls,
        every: Sequence[FreeRobot],
        t: Fraction,
        p: Any,
        rows: np.ndarray,
        state: dict[str, Any],
    ) -> tuple[np.ndarray, np.ndarray]:
        """Behaviour 4 for the copies ``every[rows]``: :meth:`_behaviour`'s floats, bit for
        bit, as arrays.

        Why: steering each copy in Python was ~26 % of a scenario2 batch. A copy draws a new
        heading and speed only every ``changePeriod`` s (scalar, from its own generator, as
        alone); between draws the steering law is arithmetic over the copies. ``math.cos``
        stays scalar: numpy may compute ``cos`` with its own SIMD code, which can differ from
        libm's (what a single run uses) in the last bit; subtraction, product, ``%`` (the
        same fmod-based rule as Python's) and comparisons are IEEE-exact in both. Where the
        extension is built the steering is one C call with the same operations and libm's
        ``cos`` (``_step.steer_random``); the numpy code is the pure path.
        """
        return cls._steer_many(p, rows, state, cls._random_draws(every, t, p, rows, state))

    @classmethod
    def _random_draws(
        cls,
        every: Sequence[FreeRobot],
        t: Fraction,
        p: Any,
        rows: np.ndarray,
        state: dict[str, Any],
    ) -> dict[str, Any]:
        """:meth:`_random_many`'s first half: the copies' steering state (built at the
        first step, or when the behaviours change), with the new heading and speed of every
        copy whose change time has come, each drawn as alone."""
        mine = state.get("random")
        if mine is not None and mine["at"] is not rows and mine["rows"] == rows.tobytes():
            mine["at"] = rows  # the same copies in a new array: behaviours changed elsewhere
        if mine is None or mine["at"] is not rows:  # first step, or behaviours changed
            comps = [every[i] for i in rows.tolist()]
            physics = comps[0].physics
            mine = state["random"] = {
                "rows": rows.tobytes(),
                "at": rows,
                "comps": comps,
                "index": physics.index_of([c.rover for c in comps]),
                "heading": np.array([c.target_heading for c in comps], dtype=np.float64),
                "factor": np.array([c.speed_factor for c in comps], dtype=np.float64),
                "soonest": min(c.next_change for c in comps),
                "soonest_s": float(min(c.next_change for c in comps)),
                # the steering below in one C call (``_step.steer_random``) where built
                "steer": _steer_random(),
            }
        comps = mine["comps"]
        # some copies draw: each as alone, from its own generator
        if at_or_after(t, mine["soonest"], mine["soonest_s"]):
            heading, factor = mine["heading"], mine["factor"]
            for k, c in enumerate(comps):
                if t >= c.next_change:
                    c._change(t)
                    heading[k] = c.target_heading
                    factor[k] = c.speed_factor
            soonest = mine["soonest"] = min(c.next_change for c in comps)
            mine["soonest_s"] = float(soonest)
        return mine  # type: ignore[no-any-return]

    @classmethod
    def _steer_many(
        cls, p: Any, rows: np.ndarray, state: dict[str, Any], mine: dict[str, Any]
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_random_many`'s second half: the steering law's wheel powers."""
        comps = mine["comps"]
        physics = comps[0].physics
        arrays = pose_arrays(physics)
        if arrays is not None:  # rovers as arrays: the headings in one read, contiguous
            angle = arrays[0][mine["index"], 2]
        else:
            angle = physics.kinematics_array(mine["index"])[:, 2]
        cruise, gain = derived(state, "_steering", (p.cruisePower, p.steerGain, rows), _rows_of)
        steer = mine["steer"]
        if steer is not None:  # the same operations as below, in C
            left, right = np.empty(len(comps)), np.empty(len(comps))
            steer(
                mine["heading"],
                angle if arrays is not None else np.ascontiguousarray(angle),
                cruise,
                mine["factor"],
                gain,
                left,
                right,
            )
            return left, right
        power = cruise * mine["factor"]
        err = (mine["heading"] - angle + math.pi) % (2 * math.pi) - math.pi  # wrap_angle
        diff = gain * err
        cos = np.fromiter(map(math.cos, err.tolist()), dtype=np.float64, count=len(comps))
        forward = power * np.where(cos > 0.0, cos, 0.0)  # max(0.0, cos): NaN gives 0.0
        return forward - diff, forward + diff

    def _change(self, t: Fraction) -> None:
        """Behaviours 3 and 4 at a change time: the next change, the new speed (and heading)."""
        p = self.p
        b = p.behavior
        period = _period(p.changePeriod)
        self.next_change = t + period
        if b == 3:
            cycle = (1.0, 0.5, 1.5, 1.0)
            self.speed_factor = cycle[int(t / period) % 4]
        elif b == 4:
            self.target_heading = self.rover.kinematics()[2] + self.rng.uniform(
                -p.randomTurn, p.randomTurn
            )
            self.speed_factor = float(self.rng.uniform(0.5, 1.2))

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
        nc = self.next_change
        # t >= next_change in integers when both are Fractions (as the engine's ``now`` and
        # every change time are): a Fraction comparison costs ~0.7 us, at every step
        if (
            t._numerator * nc._denominator >= nc._numerator * t._denominator
            if t.__class__ is Fraction and nc.__class__ is Fraction
            else t >= nc
        ):
            self._change(t)
        if b == 3:
            return cruise * self.speed_factor, cruise * self.speed_factor
        if b == 5:
            return self._waypoints(cruise)
        # self._steer(cruise * self.speed_factor, self.target_heading), inlined: behaviour 4
        # steers at every step; the rover's state read through the C step's own reader
        rover = self.rover
        source = rover._source
        angle = (source() if source is not None else rover.kinematics())[2]
        err = (self.target_heading - angle + _PI) % _TWO_PI - _PI
        diff = p.steerGain * err
        cos = _cos(err)
        forward = cruise * self.speed_factor * (cos if cos > 0.0 else 0.0)
        return forward - diff, forward + diff

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
        # wrap_angle, inlined (every step of a steering leader)
        err = (heading - self.rover.kinematics()[2] + _PI) % _TWO_PI - _PI
        diff = self.p.steerGain * err
        cos = _cos(err)
        forward = power * (cos if cos > 0.0 else 0.0)  # max(0.0, cos), NaN giving 0.0
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


def _behaviours(behavior: np.ndarray) -> tuple[list[int], np.ndarray | None] | None:
    """What a group's ``step_many`` does with each copy, from the ``behavior`` array: None
    when all cruise straight (behaviour 1); else the copies stepped one by one (circles,
    waypoints, ...) and those that steer at random (behaviour 4, None if none). Kept while
    the parameter array is the same object (``engine.batch.derived``): a few numpy calls a
    step fewer."""
    straight = behavior == 1
    if straight.all():
        return None
    random = behavior == 4
    rows = np.flatnonzero(random) if random.any() else None
    return np.flatnonzero(~straight & ~random).tolist(), rows


def _rows_of(cruise: np.ndarray, gain: np.ndarray, rows: np.ndarray) -> tuple[Any, Any]:
    """The random copies' cruise power and steering gain (kept as :func:`_behaviours`), as
    contiguous float64 arrays (what the C steering reads)."""
    f64 = np.float64
    return (
        np.ascontiguousarray(np.asarray(cruise)[rows], dtype=f64),
        np.ascontiguousarray(np.asarray(gain)[rows], dtype=f64),
    )


@functools.lru_cache(maxsize=64)
def _period(seconds: float) -> Fraction:
    """``changePeriod`` as the decimal-exact Fraction of its float (``Fraction(str(s))``),
    made once a value: every leader of a batch changes at the same instant, and parsing the
    string was ~3 µs of each change."""
    return Fraction(str(seconds))


def _leader_step(
    comps: Sequence[FreeRobot],
    p: Any,
    rows: np.ndarray,
    state: dict[str, Any],
    mine: dict[str, Any],
) -> dict[str, np.ndarray] | None:
    """A random leader group's steering, powers and poses in one C call
    (``_step.leader_step``: ``steer_random``, ``column_powers`` and ``robot_poses``' own
    arithmetic), its outputs; None where that call does not apply: the pure path, a group
    that is not every copy of a batch's columns in order, or one with a power supply (the
    first step, which sets the robot group up, goes the usual way too).

    Why: the three calls, the angles' gather and the Python around them cost ~3 µs a group
    step more than this one call, whatever the batch's size, 2.5 times a vector env's
    step."""
    fixed = state.get("_fixed")
    if fixed is None:
        return None
    physics, index = fixed[0], fixed[3]
    lead = state.get("_lead")
    if lead is None or lead[0] is not mine["index"]:
        lead = state["_lead"] = (mine["index"], _lead_call(fixed, mine))
    call = lead[1]
    if call is None:
        return None
    arrays = pose_arrays(physics)
    if arrays is None:
        return None
    step, columns = call
    cruise, gain = derived(state, "_steering", (p.cruisePower, p.steerGain, rows), _rows_of)
    kept = state.get("_lead_out")
    if kept is None or kept[0].shape[1] != len(comps):
        # the outputs' block and its rows, made once: the engine copies a group's outputs
        # into the store at once (and sends copies), so a template may reuse its arrays;
        # seven row views a step were ~1 µs
        block = np.empty((len(POSE_NAMES), len(comps)))
        kept = state["_lead_out"] = (block, dict(zip(POSE_NAMES, block, strict=True)))
    step(mine["heading"], arrays[0], arrays[1], index, cruise, mine["factor"], gain,
         columns._band, columns._model.drives, kept[0])  # fmt: skip
    return kept[1]  # type: ignore[no-any-return]


def _lead_call(fixed: tuple[Any, ...], mine: dict[str, Any]) -> tuple[Any, Any] | None:
    """``(_step.leader_step, the columns)`` where :func:`_leader_step` applies to a group
    whose robot step keeps ``fixed`` (``robots._fixed``) and whose steering is ``mine``."""
    physics, supplied, _rovers, index, poses, set_powers = fixed
    columns = getattr(set_powers, "__self__", None)
    step = getattr(_step_module(), "leader_step", None)
    if (
        supplied
        or poses is None
        or mine["steer"] is None
        or step is None
        or getattr(columns, "_powers", None) is None
        or physics.group is not columns
        or not np.array_equal(mine["index"], index)
    ):
        return None
    return step, columns


def _step_module() -> Any:
    """The compiled physics extension where the columns use it, else None."""
    from . import compiled

    return compiled._step if compiled.columns_compiled() else None


def _steer_random() -> Any:
    """``_step.steer_random`` where the extension is in use, else None (numpy's path)."""
    from . import compiled

    return getattr(compiled._step, "steer_random", None) if compiled.columns_compiled() else None
