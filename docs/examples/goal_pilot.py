"""Your first template: a pilot that steers to a goal from a GPS fix and a compass heading."""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from amsa_phys import Kind, Param, Port, Template
from amsa_phys.model.template import InitContext


class GoalPilot(Template):
    """Drive to (goalX, goalY): forward power by the distance, turn power by the bearing error."""

    kind = Kind.CONTROLLER
    inputs = (
        Port("x", 0.0, "rover x, measured (GPS)", "m"),
        Port("y", 0.0, "rover y, measured (GPS)", "m"),
        Port("heading", 0.0, "rover heading, measured (compass)", "rad"),
    )
    outputs = (
        Port("LeftPower", 0.0, "left wheel power", "%"),
        Port("RightPower", 0.0, "right wheel power", "%"),
    )
    params = (
        Param("goalX", "float", "goal x", 20.0, -1000.0, 1000.0, "m"),
        Param("goalY", "float", "goal y", 0.0, -1000.0, 1000.0, "m"),
        Param("cruise", "float", "power far from the goal", 50.0, 0.0, 100.0, "%"),
        Param("Kw", "float", "turn power per radian of bearing error", 40.0, 0.0, 500.0, "%/rad"),
        Param("radius", "float", "stop within this distance", 0.5, 0.01, 100.0, "m"),
    )

    def initialize(self, ctx: InitContext) -> None:
        """Called once before the first step, with the scenario's t = 0 values in ``self.p``."""
        self.ctx = ctx  # kept to record an event when the goal is reached
        self.arrived = False

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, float]:
        """The paper's doStep: inputs as they are at ``t`` in, powers out."""
        p = self.p
        dx, dy = p.goalX - inp["x"], p.goalY - inp["y"]
        distance = math.hypot(dx, dy)
        if distance < p.radius:
            if not self.arrived:
                self.arrived = True
                where = f"{self.path} within {p.radius} m at t={float(t)} s"
                self.ctx.record_event("arrived", where)
            return {"LeftPower": 0.0, "RightPower": 0.0}
        error = math.atan2(dy, dx) - inp["heading"]
        error = (error + math.pi) % (2 * math.pi) - math.pi  # wrapped to [-pi, pi)
        forward = min(p.cruise, 20.0 * distance) * max(0.0, math.cos(error))
        turn = p.Kw * error
        return {"LeftPower": forward - turn, "RightPower": forward + turn}

    def on_param_change(self, name: str, value: Any) -> None:
        """A new goal (from the timeline or the window) is a new mission: not arrived yet."""
        if name in ("goalX", "goalY"):
            self.arrived = False
