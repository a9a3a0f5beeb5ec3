"""DistanceMonitor: the true leader–follower distance (a sensor in the paper's model)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from ..engine import batch_bodies, libm
from ..model.params import Param
from ..model.template import Kind, Port, Template

#: a group's state before it asked for its compiled body
_UNSET = object()


class DistanceMonitor(Template):
    """Euclidean distance between the leader's and the follower's true positions.

    A sensor in the paper (it feeds the controller); also the quality-of-control signal.
    """

    kind = Kind.SENSOR
    uses_random = False
    inputs = (Port("xLeader"), Port("yLeader"), Port("xFollower"), Port("yFollower"))
    outputs = (Port("distanceFollowerToLeader", 0.0, "true distance", "m"),)

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: one distance."""
        return {
            "distanceFollowerToLeader": math.hypot(
                inp["xLeader"] - inp["xFollower"], inp["yLeader"] - inp["yFollower"]
            )
        }

    @classmethod
    def step_many(
        cls, comps: Sequence[Any], t: Fraction, inp: Mapping[str, Any], p: Any, state: Any
    ) -> tuple[Mapping[str, Any], None]:
        """``do_step`` for many copies at once (``engine/batch.py``): in one compiled call
        where built (``_groupbodies.distance``: the same differences, and ``math.hypot``
        itself on each), else the differences in numpy and ``math.hypot`` mapped."""
        # asked once a group (a caller without a state dict asks every time)
        body = _UNSET if state is None else state.get("distance", _UNSET)
        if body is _UNSET:
            body = batch_bodies.distance()
            if state is not None:
                state["distance"] = body
        xl, yl, xf, yf = inp["xLeader"], inp["yLeader"], inp["xFollower"], inp["yFollower"]
        if body is not None and type(xl) is type(yl) is type(xf) is type(yf) is np.ndarray:
            out = np.empty(len(comps))
            body(xl, yl, xf, yf, out)
            return {"distanceFollowerToLeader": out}, None
        dx = inp["xLeader"] - inp["xFollower"]
        dy = inp["yLeader"] - inp["yFollower"]
        return {"distanceFollowerToLeader": libm.hypot(dx, dy)}, None  # math.hypot's bits


class GoalMonitor(Template):
    """Distance from a rover's true position to a goal point: the quality signal of a mission."""

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    kind = Kind.OBSERVER
    inputs = (Port("posX", 0.0, "true x", "m"), Port("posY", 0.0, "true y", "m"))
    outputs = (Port("distanceToGoal", 0.0, "true distance to the goal", "m"),)
    params = (
        Param("goalX", "float", "goal x", 0.0, -1e5, 1e5, "m"),
        Param("goalY", "float", "goal y", 0.0, -1e5, 1e5, "m"),
    )
    uses_random = False

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: one distance."""
        return {
            "distanceToGoal": math.hypot(self.p.goalX - inp["posX"], self.p.goalY - inp["posY"])
        }
