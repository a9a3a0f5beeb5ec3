"""What a ROS 2 run says on stderr while it waits, so a wait is never silent.

A run waits up to ``external.START_TIMEOUT_S`` (60 s) for each node to appear on the graph;
a node that is not running (or runs in another ``ROS_DOMAIN_ID``) used to cost a minute of
silence before the fault. The line comes at once, once per node in a process (``test`` and
``sweep`` run one scenario after another with the same node: one line, not one per run);
``-q`` turns it off (:func:`quiet`). No rclpy here: the CLI imports it before ROS 2 starts.
"""

from __future__ import annotations

import os
import sys

_quiet = False
_said: set[str] = set()


def quiet() -> None:
    """No waiting lines from now on in this process (``-q``)."""
    global _quiet
    _quiet = True


def domain() -> str:
    """The ROS 2 domain this process joins, as a user would check it."""
    return os.environ.get("ROS_DOMAIN_ID") or "0 (unset)"


def say(line: str) -> None:
    """One line on stderr, at once (unless ``-q``)."""
    if not _quiet:
        print(line, file=sys.stderr, flush=True)


def waiting(node: str, seconds: float) -> None:
    """``waiting up to 60 s for ROS 2 node /Leaf (ROS_DOMAIN_ID=0 (unset))``, once per node."""
    if node in _said:
        return
    _said.add(node)
    say(f"waiting up to {seconds:g} s for ROS 2 node {node} (ROS_DOMAIN_ID={domain()})")


__all__ = ["domain", "quiet", "say", "waiting"]
