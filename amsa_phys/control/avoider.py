"""ReactiveAvoider: drive to a goal through obstacles seen by a lidar, with no map."""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

import numpy as np

from ..model.params import Param
from ..model.template import Kind, Port, Template


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


class ReactiveAvoider(Template):
    """Goal seeking with lidar obstacle avoidance: steer along the open beam nearest the goal.

    Each step, from the measured pose (``posX``, ``posY``, ``heading``: e.g. GPS and
    compass) the goal's bearing α, and for every beam direction θᵢ its *free distance*: how
    far a corridor of half-width ``halfWidth`` along θᵢ runs before a lidar return lies in
    it. A direction is *open* if it is free for ``lookahead`` m (or to the goal, if nearer).
    The steering target θ is the open direction that minimises |θᵢ − α| + ``hold`` |θᵢ −
    θ_prev| (the second term keeps the choice from flipping between two gaps); with no
    open direction, the freest one. If the goal lies outside the field of view and the
    nearest edge is open, θ = α (turn towards it). Forward power is ``cruisePower ·
    cos θ``, scaled down as the free distance straight ahead falls from ``slowDistance`` to
    ``stopDistance`` (below it the rover turns in place) and near the goal; turning power
    is ``Kw · θ``. A command whose stronger wheel is below ``minPower`` is scaled up until it
    reaches it (deadband compensation, as real drivers do: on the wheel model a rover at rest
    stays at rest below its breakaway power, so a slow creep past an obstacle's corner or
    through mud would otherwise stall for good). Within ``goalRadius`` of the goal it stops.
    A reactive law with one
    remembered angle and no map: a U-shaped trap can hold it (the obstacle course has
    none). ``angle_min``/``angle_max`` must be the lidar's: the beams' directions are
    computed from them and the number of ranges received.
    """

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    kind = Kind.CONTROLLER
    inputs = (
        Port("ranges", 0.0, "lidar ranges, beam by beam", "m", array=True),
        Port("posX", 0.0, "measured x", "m"),
        Port("posY", 0.0, "measured y", "m"),
        Port("heading", 0.0, "measured heading", "rad"),
    )
    outputs = (
        Port("LeftPower", 0.0, "left wheel power", "%"),
        Port("RightPower", 0.0, "right wheel power", "%"),
    )
    params = (
        Param("goalX", "float", "goal x", 0.0, -1e5, 1e5, "m"),
        Param("goalY", "float", "goal y", 0.0, -1e5, 1e5, "m"),
        Param(
            "goalRadius",
            "float",
            "distance at which the goal counts as reached",
            1.0,
            0.05,
            100.0,
            "m",
        ),
        Param("cruisePower", "float", "forward power when the way is clear", 25.0, 0.0, 100.0, "%"),
        Param(
            "Kw", "float", "turning power per radian of steering error", 12.0, 0.0, 500.0, "%/rad"
        ),
        Param(
            "halfWidth",
            "float",
            "half-width of the corridor a direction needs (rover + margin)",
            0.75,
            0.01,
            10.0,
            "m",
        ),
        Param(
            "lookahead",
            "float",
            "how far a direction must be free to be open",
            6.0,
            0.1,
            100.0,
            "m",
        ),
        Param(
            "slowDistance",
            "float",
            "free distance ahead below which the rover slows",
            4.0,
            0.1,
            100.0,
            "m",
        ),
        Param(
            "stopDistance",
            "float",
            "free distance ahead below which it turns in place",
            1.0,
            0.0,
            100.0,
            "m",
        ),
        Param(
            "hold",
            "float",
            "weight against changing the chosen direction (dimensionless)",
            0.5,
            0.0,
            10.0,
            "1",
        ),
        Param(
            "minPower",
            "float",
            "deadband compensation: a moving command weaker than this is scaled up to it "
            "(the motor's breakaway power; 0 = off)",
            0.0,
            0.0,
            100.0,
            "%",
        ),
        Param(
            "angle_min", "float", "the lidar's angle_min", -math.pi / 2, -math.pi, math.pi, "rad"
        ),
        Param("angle_max", "float", "the lidar's angle_max", math.pi / 2, -math.pi, math.pi, "rad"),
    )
    uses_random = False

    def initialize(self, ctx: Any) -> None:
        """No direction chosen yet."""
        self.theta_prev = 0.0

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: wheel powers from one scan and the measured pose."""
        p = self.p
        dx, dy = p.goalX - inp["posX"], p.goalY - inp["posY"]
        dist = math.hypot(dx, dy)
        if dist < p.goalRadius:
            return {"LeftPower": 0.0, "RightPower": 0.0}
        alpha = _wrap(math.atan2(dy, dx) - inp["heading"])
        ranges = np.asarray(inp["ranges"], dtype=float)
        n = len(ranges)
        angles = np.linspace(p.angle_min, p.angle_max, n) if n > 1 else np.array([p.angle_min])
        free = self.free_distance(angles, np.where(ranges > 0.0, ranges, np.inf))  # 0: no scan
        open_ = free >= min(p.lookahead, dist)
        if open_.any():
            cost = np.abs(angles - alpha) + p.hold * np.abs(angles - self.theta_prev)
            i = int(np.argmin(np.where(open_, cost, np.inf)))
            theta = float(angles[i])
            edge = (alpha < angles[0] and i == 0) or (alpha > angles[-1] and i == n - 1)
            if edge:
                theta = alpha
        else:
            i = int(np.argmax(free))
            theta = float(angles[i])
        self.theta_prev = theta
        ahead = float(min(free[int(np.argmin(np.abs(angles)))], free[i]))
        room = (ahead - p.stopDistance) / max(p.slowDistance - p.stopDistance, 1e-9)
        slow = min(1.0, max(0.0, room), max(0.3, dist / 3.0))
        forward = p.cruisePower * slow * max(0.0, math.cos(theta))
        turn = p.Kw * theta
        left, right = forward - turn, forward + turn
        strongest = max(abs(left), abs(right))
        if 0.0 < strongest < p.minPower:  # below breakaway the rover would sit still
            left, right = left * p.minPower / strongest, right * p.minPower / strongest
        return {"LeftPower": left, "RightPower": right}

    def free_distance(self, angles: np.ndarray, ranges: np.ndarray) -> np.ndarray:
        """For each beam direction, how far its corridor runs before a return lies in it."""
        rel = angles[None, :] - angles[:, None]  # return j seen from candidate direction i
        finite = np.isfinite(ranges)
        r = np.where(finite, ranges, 0.0)[None, :]
        along = r * np.cos(rel)
        across = np.abs(r * np.sin(rel))
        blocking = finite[None, :] & (along > 0) & (across < self.p.halfWidth)
        return np.where(blocking, along, np.inf).min(axis=1)
