"""The nodes an exported ROS 2 package runs end even when a signal's wake-up is missed.

``rclpy.spin`` waits without a timeout: a signal landing as a wait begins can leave the
context down and the wait never woken (``amsa_phys/ros/ros2/spin.py``). What must hold is
that every wait :func:`spin_until_shutdown` makes is bounded, so a context that goes down
with nobody waking the wait still ends the loop. A stand-in executor plays the wait (no
rclpy needed: this runs in the quick tier); the signal path itself is exercised with real
rclpy in ``test_ros2_shutdown_docs.py``.
"""

from __future__ import annotations

import sys
import types
from typing import Any

import pytest

from amsa_phys.ros.ros2.spin import LOOK_S, spin_until_shutdown


class Context:
    def __init__(self) -> None:
        self.up = True

    def ok(self) -> bool:
        return self.up


class Node:
    def __init__(self) -> None:
        self.context = Context()


def fake_executors(monkeypatch: pytest.MonkeyPatch, waits: list[Any], down_after: int) -> None:
    """``rclpy.executors`` with an executor whose wait never returns unless bounded; the
    context goes down during wait number ``down_after`` and nothing wakes that wait."""

    class SingleThreadedExecutor:
        def __init__(self, context: Context) -> None:
            self.context, self.nodes = context, []

        def add_node(self, node: Node) -> None:
            self.nodes.append(node)

        def remove_node(self, node: Node) -> None:
            self.nodes.remove(node)

        def spin_once(self, timeout_sec: float | None = None) -> None:
            waits.append(timeout_sec)
            if len(waits) == down_after:
                self.context.up = False  # the signal's shutdown; its wake-up is lost
            if timeout_sec is None:
                raise AssertionError("an unbounded wait: the node would wait for ever")

    module = types.ModuleType("rclpy.executors")
    module.SingleThreadedExecutor = SingleThreadedExecutor  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "rclpy", types.ModuleType("rclpy"))
    monkeypatch.setitem(sys.modules, "rclpy.executors", module)


@pytest.mark.parametrize("down_after", [1, 5])
def test_a_lost_wake_up_ends_the_loop_at_the_next_bounded_wait(
    monkeypatch: pytest.MonkeyPatch, down_after: int
) -> None:
    waits: list[Any] = []
    fake_executors(monkeypatch, waits, down_after)
    spin_until_shutdown(Node())
    # every wait bounded, and the loop ended at the first look after the context went down
    assert waits == [LOOK_S] * down_after
    assert 0 < LOOK_S <= 1


def test_a_context_already_down_does_not_wait(monkeypatch: pytest.MonkeyPatch) -> None:
    waits: list[Any] = []
    fake_executors(monkeypatch, waits, down_after=0)
    node = Node()
    node.context.up = False
    spin_until_shutdown(node)
    assert waits == []
