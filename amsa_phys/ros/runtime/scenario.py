"""The scenario node: the timeline applied to the parameter server, in simulated time.

It follows ``/clock``; when simulated time reaches one of the timeline's points (a phase's
start or a change inside a phase, ``new_phase: false``: ``Timeline.points``) it sets that
point's parameters (``/Leaf/param``, each value judged when the scenario was loaded) and
announces how many points it has applied on ``names.PHASE``. The simulator waits for that
count at the point's instant before any component due then runs, so in lockstep the change
lands exactly where ``amsa-phys run`` applies it; in free mode the nodes pick it up at their
next step.
"""

from __future__ import annotations

import time
from typing import Any

from ...errors import AmsaError
from .. import names
from . import notready, rosio, startup
from .config import load_config


def main() -> None:
    """The scenario node's entry point."""
    rospy = rosio.ros()
    startup.init_node(rospy, names.SCENARIO)
    _, String, _ = rosio.msgs()
    try:
        cfg = load_config(rospy)
    except AmsaError as exc:
        rosio.fail(rospy, f"{names.SCENARIO}: {exc}")
        return
    clock = rosio.ClockFollower(rospy)
    gate = rosio.Gate(rospy)
    ack = gate.publisher(names.PHASE, String, 1, latch=True)
    started = time.monotonic()
    missing = gate.wait(cfg.timeout * 2)
    if rospy.is_shutdown():
        return
    if missing:
        rosio.fail(rospy, notready.message(names.SCENARIO, gate, started))
    keep: Any = rosio.announce_ready(rospy, names.SCENARIO)
    startup.started(rospy)
    for k, point in enumerate(cfg.scenario.timeline.points(), start=1):
        if not clock.wait_until(rosio.to_ns(point.at)):
            return
        for change in point.changes:
            rospy.set_param(names.param(change.leaf, change.param), rosio.ros_value(change.value))
        ack.publish(String(str(k)))
        what = f"phase {point.phase}" if point.starts_phase else f"in phase {point.phase}"
        text = ", ".join(f"{c.key}={c.value}" for c in point.changes)
        print(f"{names.SCENARIO}: {what} at t={float(point.at):g} s: {text}", flush=True)
    rospy.spin()
    del keep
