"""The adapt node: ``adapt:`` rules on a robot (``sim:=false``), with no simulator to run them.

With the simulator (``sim:=true``) the rules fire inside it, at the engine's exact instants,
and the run stays byte-identical with ``amsa-phys run`` in lockstep (``simulator.py``). On a
robot nothing steps the world, so this node reads the estimators' topics and, each time one
of the rules' signals brings a new value, asks the engine's own :class:`AdaptRules` (same
conditions, hold times, least time between switches) at ``/clock``'s time; a firing puts
the rule's values on the parameter server, where each node takes them at its next step.
Every firing is logged (``rosout``) with the estimates that triggered it, as the run's
``adapt`` event says.

``rules:=node`` (lockstep, with the simulator) runs the rules here instead of in the
simulator, so this very node is checked against ``amsa-phys run``: at every instant at which
the engine would ask its rules, the simulator sends ``due SEQ NUM DEN C1..Cn`` on
``names.step_topic(NODE)`` (the instant, and how many messages of each signal's topic, in
sorted order, are visible then, as a Leaf's step request says); the node evaluates the rules
on message number Ci of each, puts a firing's values on the parameter server, and answers on
``names.done_topic(NODE)`` ``done SEQ`` or ``fire SEQ RULE DETAIL`` (the rule's number and the
event's text); the simulator applies the rule's changes then, as the engine does.
"""

from __future__ import annotations

import threading
import time
from fractions import Fraction
from typing import Any

from ...engine.adapt import AdaptRules
from ...errors import AmsaError
from .. import names
from . import notready, rosio, startup
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
        self.lockstep = cfg.rules_node
        self.timeout = cfg.timeout
        self.rules = AdaptRules(cfg.scenario.adapt, self._current)
        self.signals = signals = sorted({c.signal for r in cfg.scenario.adapt for c in r.when})
        self.values = {s: float(world.buffers[s].initial) for s in signals}
        self.lock = threading.Lock()
        Float64, String, _ = rosio.msgs()
        self.String = String
        #: lockstep: messages received per signal, each one kept (by number) while a
        #: request may still ask for it; the request waiting for its messages
        self.count = dict.fromkeys(signals, 0)
        self.kept: dict[str, dict[int, float]] = {s: {0: self.values[s]} for s in signals}
        self.pending: list[str] | None = None
        self.gate = rosio.Gate(rospy)
        if self.lockstep:
            self.done = self.gate.publisher(names.done_topic(NODE), String, 1)
            self.step_sub = rospy.Subscriber(
                names.step_topic(NODE), String, self._on_request, tcp_nodelay=True
            )
        self.subs = [
            rospy.Subscriber(
                names.topic(s), Float64, self._on_data, callback_args=s, tcp_nodelay=True
            )
            for s in signals
        ]

    def _current(self, leaf: str, param: str) -> Any:
        """The value in force: the server's (what the nodes read). In lockstep asked of the
        master itself: the cache is updated asynchronously, and a timeline change made at
        this very instant must count."""
        p = self.graph.leaf(leaf).template.param(param)
        return rosio.read_param(self.rospy, leaf, p, cached=not self.lockstep)

    def _on_data(self, msg: Any, signal: str) -> None:
        with self.lock:
            if self.lockstep:
                self.count[signal] += 1
                self.kept[signal][self.count[signal]] = msg.data
                if self.pending is not None:
                    self._try()
                return
            self.values[signal] = msg.data
            ns = self.rospy.Time.now().to_nsec()
            self._fire(Fraction(ns, 10**9))

    def _fire(self, t: Fraction) -> tuple[int, str] | None:
        """Ask the rules at ``t`` on :attr:`values`; a firing goes on the parameter server."""
        firing = self.rules.due(t, self.values)
        if firing is None:
            return None
        for change in firing.rule.changes:
            rosio.set_param(self.rospy, change.leaf, change.param, change.value)
        self.rospy.loginfo(f"adapt at t={float(t):g} s: {firing.detail()}")
        return firing.rule.number, firing.detail()

    # -- lockstep (rules:=node) ---------------------------------------------------------------
    def _on_request(self, msg: Any) -> None:
        with self.lock:
            self.pending = msg.data.split(" ")
            self._try()

    def _try(self) -> None:
        """Answer the pending request once its messages are in (the lock is held)."""
        req = self.pending
        assert req is not None
        seq, t = req[1], Fraction(int(req[2]), int(req[3]))
        counts = [int(c) for c in req[4:]]
        if any(self.count[s] < c for s, c in zip(self.signals, counts, strict=True)):
            return  # a message is still on its way
        self.pending = None
        for s, c in zip(self.signals, counts, strict=True):
            kept = self.kept[s]
            self.values[s] = kept[c]  # message number c is what the rules see now
            for old in [k for k in kept if k < c]:
                del kept[old]
        try:
            fired = self._fire(t)
        except AmsaError as exc:
            self.done.publish(self.String(f"error {seq} {exc}"))
            return
        text = f"done {seq}" if fired is None else f"fire {seq} {fired[0]} {fired[1]}"
        self.done.publish(self.String(text))


def main() -> None:
    """The adapt node's entry point."""
    rospy = rosio.ros()
    startup.init_node(rospy, NODE)
    try:
        node = AdaptNode(rospy)
        if node.lockstep:
            started = time.monotonic()
            missing = node.gate.wait(node.timeout * 2)
            if rospy.is_shutdown():
                return
            if missing:
                rosio.fail(rospy, notready.message(NODE, node.gate, started))
            keep = rosio.announce_ready(rospy, NODE)
    except AmsaError as exc:
        rosio.fail(rospy, f"{NODE}: {exc}")
        return
    startup.started(rospy)
    rospy.spin()
    if node.lockstep:
        del keep
