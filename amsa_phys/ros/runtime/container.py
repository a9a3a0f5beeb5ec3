"""Lockstep with the C++ container: the simulator's side of one message a wave.

The C++ Leaves hosted by ``amsa_leaves`` (``graph.shared``) are not asked one topic each:
the requests of a wave go out in one message on ``rosnames.STEP_CONTAINER``, a line a Leaf
(``/LEAF step SEQ NUM DEN C1..Cn``, ``/LEAF param SEQ NAME``), and the container answers
for all of them in one message on ``rosnames.DONE_CONTAINER`` (``/LEAF ANSWER`` a line; the
protocol's other half is ``files/amsa_leaf_node.h``'s Dispatcher). A step's answer carries
the values the Leaf published (``done SEQ I J .. | VI VJ ..``, C hex floats), so the
simulator takes them from it instead of subscribing to each output. Split from
``simulator.py``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .. import names


class Container:
    """The requests to the container's Leaves, sent a wave at a time, and their answers."""

    def __init__(
        self,
        rospy: Any,
        gate: Any,
        String: Any,
        shared: frozenset[str],
        on_answers: Callable[[list[tuple[str, str]]], None],
    ) -> None:
        self.shared = shared
        self.String = String
        self.lines: list[str] = []
        self.paths = {names.ns(p): p for p in shared}
        self.on_answers = on_answers
        if shared:
            self.pub = gate.publisher(names.step_topic(names.CONTAINER), String, 1)
            self.sub = rospy.Subscriber(
                names.done_topic(names.CONTAINER), String, self._on_done, tcp_nodelay=True
            )

    def add(self, path: str, request: str) -> None:
        """One Leaf's request, sent with the others of the wave by :meth:`send`."""
        self.lines.append(f"{names.ns(path)} {request}")

    def send(self) -> None:
        """The requests added so far, in one message."""
        if self.lines:
            self.pub.publish(self.String("\n".join(self.lines)))
            self.lines = []

    def _on_done(self, msg: Any) -> None:
        answers = []
        for line in msg.data.split("\n"):
            node, _, answer = line.partition(" ")
            if node in self.paths:
                answers.append((self.paths[node], answer))
        self.on_answers(answers)


def stepped(text: str, outputs: list[str]) -> list[tuple[str, float]]:
    """The outputs a container Leaf published in a step and their values, from the text of
    its answer after ``done SEQ``: ``I J .. | VI VJ ..``."""
    indexes, _, values = text.partition("|")
    got = [outputs[int(i)] for i in indexes.split()]
    return list(zip(got, [float.fromhex(v) for v in values.split()], strict=True))
