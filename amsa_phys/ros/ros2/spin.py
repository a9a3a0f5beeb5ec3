"""Spinning a node until a signal ends it, without ``rclpy.spin``'s missed wake-up.

``rclpy.spin`` waits without a timeout. rclpy's own signal handler (SIGINT, SIGTERM) shuts
the context down and wakes that wait; when the signal lands just as a wait begins, the
wake-up can be missed and the process waits for ever with its context already down (seen
with rclpy 9: a node sent SIGTERM just after it appeared on the graph, now and then, and
more often on a loaded machine). A wait bounded by :data:`LOOK_S` looks at the context
again, so a node ends within that time of the signal whatever the timing. The nodes an
exported package runs (``leafnode.py``, ``robot.py``) spin here; ``docs/ros2.md`` shows
users the same loop.
"""

from __future__ import annotations

from typing import Any

#: the longest a wait lasts before the context is looked at again (seconds)
LOOK_S = 0.1


def spin_until_shutdown(node: Any) -> None:
    """Execute ``node``'s callbacks until its context is shut down (a signal, or
    ``rclpy.shutdown``). Raises what the executor raises on the way out
    (``ExternalShutdownException``, ``KeyboardInterrupt``): the caller treats both as a
    normal end."""
    from rclpy.executors import SingleThreadedExecutor

    executor = SingleThreadedExecutor(context=node.context)
    executor.add_node(node)
    try:
        while node.context.ok():
            executor.spin_once(timeout_sec=LOOK_S)
    finally:
        executor.remove_node(node)


__all__ = ["LOOK_S", "spin_until_shutdown"]
