"""``rules:=node``: the simulator asks the adapt node for the ``adapt:`` rule due at an instant.

By default the rules fire inside the simulator (``engine/adapt.py``, at the engine's exact
instants). With ``rules:=node`` in lockstep, the simulator asks the ``amsa_adapt`` node
(``adapt.py``, the node a robot runs with ``sim:=false``) instead, at every instant at which
the engine would ask its own rules, with the message counts of the rules' signals visible
then; the node's answer is applied as the engine applies a firing (the rule's changes, the
``adapt.rule`` trace column, the ``adapt`` event with the node's text). So the adapt node is
held to ``amsa-phys run``: same firings, same instants, byte-identical trace.
"""

from __future__ import annotations

from fractions import Fraction
from typing import TYPE_CHECKING

from ...engine.face import SimView
from ...errors import RunFault
from .. import names
from .adapt import NODE

if TYPE_CHECKING:  # the simulator node imports this module
    from .simulator import Link


def attach(link: Link) -> None:
    """The simulator's side of the adapt node's protocol (only with ``rules:=node``): its
    request publisher, its answers, and the node among those the run waits for."""
    if not link.cfg.rules_node:
        return
    link.replies[NODE] = None
    link.step_pubs[NODE] = link.gate.publisher(names.step_topic(NODE), link.String, 1)
    link.subs.append(
        link.rospy.Subscriber(
            names.done_topic(NODE),
            link.String,
            link._on_done,
            callback_args=NODE,
            tcp_nodelay=True,
        )
    )
    link.expected_ready.add(NODE)


def due(link: Link, sim: SimView, t: Fraction) -> tuple[int, str] | None:
    """The rule the adapt node fires at ``t`` (its number and the event's text), or None."""
    signals = sorted(link.graph.adapt_signals)
    counts = " ".join(str(link.published[s] - sim.in_flight(s)) for s in signals)
    head = link._request(NODE, "due", f"{t.numerator} {t.denominator} {counts}", t, "the rules")
    if head[0] == "error":
        raise RunFault(NODE, t, head[2] if len(head) > 2 else "error")
    if head[0] != "fire":
        return None
    number, _, detail = head[2].partition(" ")
    return int(number), detail
