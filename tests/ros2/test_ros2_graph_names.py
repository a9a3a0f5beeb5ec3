"""A driver publishing the wrong type on a sensor topic is named in the one line that says so,
even when the ROS graph lists its publisher before it has discovered the publisher's node
(rmw's ``_NODE_NAME_UNKNOWN_``, seen on a loaded machine): the line waits for the name, and
after ``UNNAMED_LOOKS`` looks says it without one. No ROS needed: the graph is a stand-in."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from amsa_phys.ros.ros2.robot import UNKNOWN_NODE, UNNAMED_LOOKS, Boundary


class _Graph:
    """A node whose graph answers from a script, one answer a look, and logs warnings."""

    def __init__(self, answers: list[list[Any]]) -> None:
        self.answers = answers
        self.said: list[str] = []

    def get_publishers_info_by_topic(self, topic: str) -> list[Any]:
        return self.answers.pop(0) if len(self.answers) > 1 else self.answers[0]

    def get_logger(self) -> Any:
        return SimpleNamespace(warning=self.said.append)


def _looks(names: list[str], looks: int) -> list[str]:
    infos = [[SimpleNamespace(node_name=n, topic_type="std_msgs/msg/String")] for n in names]
    node = _Graph(infos)
    src = SimpleNamespace(
        topic="/Leader/LeaderGPS/fix", role=SimpleNamespace(msg="sensor_msgs/NavSatFix")
    )
    bridge = SimpleNamespace(
        robot=SimpleNamespace(inbound=[src]), node=node, wrong_types=set(), unnamed={}
    )
    for _ in range(looks):
        Boundary._look_at_graph(bridge)  # type: ignore[arg-type]
    return node.said


LINE = (
    "{} publishes std_msgs/msg/String on /Leader/LeaderGPS/fix, expected "
    "sensor_msgs/msg/NavSatFix: its messages are not read"
)


def test_the_line_waits_for_the_publishers_name() -> None:
    said = _looks([UNKNOWN_NODE, UNKNOWN_NODE, "hostile_driver"], looks=5)
    assert said == [LINE.format("hostile_driver")]


def test_a_publisher_never_named_is_said_without_a_name_once() -> None:
    said = _looks([UNKNOWN_NODE], looks=UNNAMED_LOOKS + 5)
    assert said == [LINE.format("a node the ROS graph does not name")]
