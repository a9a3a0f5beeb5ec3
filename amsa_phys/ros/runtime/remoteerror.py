"""A Leaf node's exception, as the simulator raises it in its run.

Why its own class: the engine reports a component's fault by the exception's repr, and a
node's answer carries the repr the node made; raising it as this class keeps that text as
it was, whatever the exception's type in the node's process.
"""

from __future__ import annotations


class RemoteError(Exception):
    """An exception a node's ``do_step`` raised, shown as the node showed it (its repr)."""

    def __init__(self, text: str) -> None:
        super().__init__(text)
        self.text = text

    def __repr__(self) -> str:
        return self.text
