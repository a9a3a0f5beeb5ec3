"""What a node says when its readers never connected: which topics, after how long, and why.

Every node waits at start until each of its publishers has the subscribers the graph expects
(``rosio.Gate``). The simulator reads every one of those topics, so when it fails to start
(no ``AMSA_PHYS_PYTHON``, amsa-phys not importable, an ``out:=`` it refuses) the others wait
for it in vain. roslaunch normally stops them as soon as the simulator, a required node,
ends; a node that does give up must not say only "not connected": it names each topic still
short of subscribers, the time it actually waited, and points at the simulator's own error,
which is the cause (the C++ Leaves say the same: ``amsa_leaf_node.h``).
"""

from __future__ import annotations

import time
from typing import Any

from .. import names


def short(gate: Any) -> list[str]:
    """``/T (1 of 3 subscribers)`` for each of the gate's topics still short of readers."""
    return [
        f"{topic} ({pub.get_num_connections()} of {want} subscribers)"
        for pub, want, topic in gate.pubs
        if pub.get_num_connections() < want
    ]


def message(who: str, gate: Any, started: float) -> str:
    """The one line of a node that gave up waiting (``started``: ``time.monotonic()``)."""
    waited = time.monotonic() - started
    topics = ", ".join(short(gate)) or "(none: the node was told to stop)"
    return (
        f"{who}: gave up after {waited:.1f} s waiting for the readers of {topics}; "
        f"{names.SIMULATOR} reads each of them: if it did not start, its own error (above, "
        "or in its log) says why"
    )
