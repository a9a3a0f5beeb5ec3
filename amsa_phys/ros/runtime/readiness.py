"""Free mode: when a node that does not announce itself on ``names.READY`` is ready.

Every generated node says on ``names.READY`` that its publishers have all their subscribers
(ROS 1 drops what is published before a subscriber connects). A user's own node need not: in
free mode the simulator waits for its topics instead: each output the node publishes is
connected to the simulator and has as many subscribers registered with the master as the
graph expects (such a node made the run abort after 120 s).
"""

from __future__ import annotations

import xmlrpc.client
from typing import Any

from .. import names
from ..graph import RosGraph


def registered_subscribers(rospy: Any) -> dict[str, int]:
    """Subscribers of every topic, as the master has them registered."""
    try:
        code, _, state = rospy.get_master().target.getSystemState(rospy.get_name())
    except (OSError, xmlrpc.client.Error):  # the master is going away: nothing is up
        return {}
    return {topic: len(nodes) for topic, nodes in state[1]} if code == 1 else {}


def topics_up(
    graph: RosGraph, data_subs: dict[str, Any], path: str, subscribers: dict[str, int]
) -> bool:
    """Every output of Leaf ``path`` is published to the simulator and fully subscribed."""
    for b in graph.outputs(path):
        if data_subs[b].get_num_connections() < 1:
            return False
        if subscribers.get(names.topic(b), 0) < graph.subscribers(b):
            return False
    return True
