"""The adapt node: ``adapt:`` rules on a robot (``sim:=false``), with no simulator to run them.

With the simulator (``sim:=true``) the rules fire inside it, at the engine's exact instants,
and the run stays byte-identical with ``amsa-phys run`` in lockstep (``simulator.py``). On a
robot nothing steps the world, so this node reads the estimators' topics and, each time one
of the rules' signals brings a new value, asks the engine's own :class:`AdaptRules` (same
conditions, hold times, least time between switches) at ``/clock``'s time; a firing puts
the rule's values on the parameter server, where each node takes them at its next step.
Every firing is logged (``rosout``) with the estimates that triggered it, as the run's
``adapt`` event says.
"""

from __future__ import annotations

import threading
from fractions import Fraction
from typing import Any

from ...engine.adapt import AdaptRules
from ...errors import AmsaError
from .. import names
from . import rosio
from .config import load_config

#: The node's name (a Leaf cannot take it: ``names.RESERVED``).
NODE = "amsa_adapt"


class AdaptNode:
    """The scenario's rules against the latest estimates on their topics."""

    def __init__(self, rospy: Any) -> None:
        self.rospy = rospy
        cfg = load_config(rospy)
        world = cfg.scenario.world
        self.graph = cfg.graph
        self.rules = AdaptRules(cfg.scenario.adapt, self._current)
        signals = sorted({c.signal for r in cfg.scenario.adapt for c in r.when})
        self.values = {s: float(world.buffers[s].initial) for s in signals}
        self.lock = threading.Lock()
        Float64 = rosio.msgs()[0]
        self.subs = [
            rospy.Subscriber(names.topic(s), Float64, self._on_data, callback_args=s)
            for s in signals
        ]

    def _current(self, leaf: str, param: str) -> Any:
        """The value in force: the server's (what the nodes read)."""
        return rosio.read_param(
            self.rospy, leaf, self.graph.leaf(leaf).template.param(param), cached=True
        )

    def _on_data(self, msg: Any, signal: str) -> None:
        with self.lock:
            self.values[signal] = msg.data
            ns = self.rospy.Time.now().to_nsec()
            firing = self.rules.due(Fraction(ns, 10**9), self.values)
            if firing is None:
                return
            for change in firing.rule.changes:
                rosio.set_param(self.rospy, change.leaf, change.param, change.value)
            self.rospy.loginfo(f"adapt at t={ns / 1e9:g} s: {firing.detail()}")


def main() -> None:
    """The adapt node's entry point."""
    rospy = rosio.ros()
    rospy.init_node(NODE)
    try:
        AdaptNode(rospy)
    except AmsaError as exc:
        rosio.fail(rospy, f"{NODE}: {exc}")
        return
    rospy.spin()
