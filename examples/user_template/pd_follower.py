"""A user template: a PD follower controller, loaded by a world as ``pd_follower:PDFollower``.

The paper's proportional law (``FollowerController``) oscillates in the nominal context at
Kv = 0.35: a distance measured at 4 Hz reaches the wheels 1 s later. A derivative term on
the distance error (the closing speed) damps that. Run it with::

    PYTHONPATH=examples/user_template amsa-phys run examples/user_template/scenario.yaml --headless

Everything a template needs comes from ``amsa_phys``: the base class, the kind, the ports and
the parameters. The declaration is data (``amsa-phys templates pd_follower:PDFollower``
prints it without running anything); the behaviour is ``initialize`` and ``do_step``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from amsa_phys import Kind, Param, Port, Template


class PDFollower(Template):
    """PD follower: Kp on the distance error, Kd on its rate, Kw on the bearing error."""

    kind = Kind.CONTROLLER  # process, environment, sensor, actuator, controller or observer
    # Port(name, initial=0.0, description="", unit=""): inputs are linked in the world file
    inputs = (
        Port("xLeader", 0.0, "leader x (GPS)", "m"),
        Port("yLeader", 0.0, "leader y (GPS)", "m"),
        Port("xFollower", 0.0, "follower x (GPS)", "m"),
        Port("yFollower", 0.0, "follower y (GPS)", "m"),
        Port("headingFollower", 0.0, "follower heading (compass)", "rad"),
        Port("distanceLeaderFollower", 0.0, "leader-follower distance", "m"),
    )
    # an output's ``initial`` is what its Data buffer holds before the first step
    outputs = (
        Port("LeftPower", 0.0, "left wheel power", "%"),
        Port("RightPower", 0.0, "right wheel power", "%"),
    )
    # Param(name, type, description, default, min, max, unit): every value a world, a
    # scenario, --set or the window gives is checked against type and [min, max]
    params = (
        Param("Kp", "float", "gain on the distance error", 0.35, 0.0, 10.0, "1/m"),
        Param("Kd", "float", "gain on the rate of the distance error", 0.5, 0.0, 10.0, "s/m"),
        Param("Kw", "float", "gain on the bearing error", 0.04, 0.0, 10.0, "1/rad"),
        Param("distanceRef", "float", "reference distance to the leader", 15.0, 0.0, 1000.0, "m"),
    )

    def initialize(self, ctx: Any) -> None:
        """The paper's initialize(): no previous error yet (``ctx.rng`` would be our own
        random stream, ``ctx.path`` our name; this controller needs neither)."""
        self.last: tuple[float, float] | None = None  # (t, error) of the previous step

    def do_step(self, t: Fraction, inp: Mapping[str, float]) -> Mapping[str, float]:
        """The paper's doStep: read the inputs, return the outputs to publish.

        Called at the component's frequency with the inputs as they are at ``t``; what it
        returns is published at the end of the step (a missing key publishes nothing).
        """
        p = self.p  # current parameter values: the timeline may change them mid-run
        d = inp["distanceLeaderFollower"]
        if d <= 0.0:  # nothing measured yet
            return {"LeftPower": 0.0, "RightPower": 0.0}
        e = d - p.distanceRef
        rate = 0.0
        if self.last is not None and float(t) > self.last[0]:
            rate = (e - self.last[1]) / (float(t) - self.last[0])
        self.last = (float(t), e)
        alpha = math.atan2(inp["yLeader"] - inp["yFollower"], inp["xLeader"] - inp["xFollower"])
        alpha = (alpha - inp["headingFollower"] + math.pi) % (2 * math.pi) - math.pi
        forward = 100.0 * (p.Kp * e + p.Kd * rate) * math.cos(alpha)
        turn = 100.0 * p.Kw * alpha
        return {"LeftPower": forward - turn, "RightPower": forward + turn}

    @classmethod
    def step_many(
        cls,
        comps: Sequence[PDFollower],
        t: Fraction,
        inp: Mapping[str, np.ndarray],
        p: Any,
        state: dict[str, Any],
    ) -> tuple[dict[str, np.ndarray], np.ndarray | None]:
        """Optional: ``do_step`` for many copies at once (a ``count:`` Composite of 32 or more).

        ``inp`` and ``p`` hold one array entry per copy; ``state`` is ours to keep per-group
        arrays in. Returns one array per output and a mask of the copies that publish
        (None: all). The engine calls either this or ``do_step`` for a given leaf, never both.
        """
        n = len(comps)
        d = inp["distanceLeaderFollower"]
        e = d - p.distanceRef
        now = float(t)
        if "last_t" not in state:
            state["last_t"] = np.full(n, np.nan)
            state["last_e"] = np.zeros(n)
        measured = d > 0.0
        dt = now - state["last_t"]
        has_last = measured & (dt > 0)  # NaN (no previous step) compares False
        rate = np.zeros(n)
        rate[has_last] = (e[has_last] - state["last_e"][has_last]) / dt[has_last]
        state["last_t"] = np.where(measured, now, state["last_t"])
        state["last_e"] = np.where(measured, e, state["last_e"])
        alpha = np.arctan2(inp["yLeader"] - inp["yFollower"], inp["xLeader"] - inp["xFollower"])
        alpha = (alpha - inp["headingFollower"] + np.pi) % (2 * np.pi) - np.pi
        forward = 100.0 * (p.Kp * e + p.Kd * rate) * np.cos(alpha)
        turn = 100.0 * p.Kw * alpha
        left = np.where(measured, forward - turn, 0.0)
        right = np.where(measured, forward + turn, 0.0)
        return {"LeftPower": left, "RightPower": right}, None
