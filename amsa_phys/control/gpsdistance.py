"""GpsDistance: the leader-follower distance as the follower can know it, from two GPS fixes.

The 2019 model feeds the controller's ``distanceLeaderFollower`` from ``MyDistanceMonitor``,
the *true* distance between the rovers: GPS noise and lost fixes then only reach the
bearing, and a 90 % GPS loss barely moves the paper's Fig. 6 (issue 31, 5). A real follower
has no such oracle. This component computes the distance from the fixes the controller
already reads, so a lost leader fix (the GPS publishes nothing and its consumers keep the
stale fix) is a stale distance, and GPS noise is distance noise. ``worlds/
mde_challenge_sensed.yaml`` wires it in; ``MyDistanceMonitor`` stays the judge (the quality
signal is the true distance).

A controller, not a sensor: in the AMSA style a sensor feeds only controllers and observers
(``model/links.py``), and this reads two sensors' outputs; it is the first stage of a
cascade whose second stage is the follower law.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

from ..engine import libm
from ..model.template import Kind, Port, Template


class GpsDistance(Template):
    """Euclidean distance between the leader's and the follower's GPS fixes."""

    kind = Kind.CONTROLLER
    uses_random = False
    inputs = (
        Port("xLeader", 0.0, "leader x (GPS fix)", "m"),
        Port("yLeader", 0.0, "leader y (GPS fix)", "m"),
        Port("xFollower", 0.0, "follower x (GPS fix)", "m"),
        Port("yFollower", 0.0, "follower y (GPS fix)", "m"),
    )
    outputs = (Port("distanceFollowerToLeader", 0.0, "distance between the two fixes", "m"),)

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: one distance, from the latest fixes (stale if one was lost)."""
        return {
            "distanceFollowerToLeader": math.hypot(
                inp["xLeader"] - inp["xFollower"], inp["yLeader"] - inp["yFollower"]
            )
        }

    @classmethod
    def step_many(
        cls, comps: Sequence[Any], t: Fraction, inp: Mapping[str, Any], p: Any, state: Any
    ) -> tuple[Mapping[str, Any], None]:
        """``do_step`` for many copies at once (``engine/batch.py``), bit for bit."""
        dx = inp["xLeader"] - inp["xFollower"]
        dy = inp["yLeader"] - inp["yFollower"]
        return {"distanceFollowerToLeader": libm.hypot(dx, dy)}, None
