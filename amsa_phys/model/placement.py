"""Which Leaves must live where the physics is: found by asking them, not by a list.

A Leaf whose ``initialize`` asks for a shared service of the run (``ctx.shared``: the pymunk
world) or adds an engine hook cannot step alone, outside the simulator: a rover's body, a
lidar casting rays. :func:`classify` finds out by initializing each Leaf with a context that
refuses those two calls, so a new template that needs the physics is placed right without
anyone listing it. The ROS exports (``ros/graph.py``) place their nodes with it, and the
loader refuses ``ros2:``/``--ros2`` on such a Leaf with it; the random stream a Leaf draws
from while initializing is the caller's (the ROS nodes' is the run's own).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from ..errors import ConfigError
from .world import WorldSpec


class NeedsSimulator(Exception):
    """A Leaf asked for the simulator's shared services while initializing."""


class AloneContext:
    """What a Leaf's ``initialize`` gets away from the simulator: a random stream, no shared
    world. ``events`` collects what the Leaf records (a ROS node sends them on)."""

    def __init__(self, path: str, world: WorldSpec, rng: Any) -> None:
        self.path = path
        self.rng = rng
        self.world = world
        self.events: list[tuple[str, str]] = []

    def shared(self, name: str, factory: Any) -> Any:
        """Shared services live in the simulator."""
        raise NeedsSimulator(name)

    def add_hook(self, rate_hz: Any, fn: Any, name: str) -> None:
        """Engine hooks live in the simulator."""
        raise NeedsSimulator(name)

    def record_event(self, kind: str, detail: str) -> None:
        """Kept until whoever runs the Leaf passes them on."""
        self.events.append((kind, detail))


def classify(
    world: WorldSpec,
    context: Callable[[str], AloneContext],
    paths: Iterable[str] | None = None,
) -> list[str]:
    """The Leaves (of ``paths``, default all) that must run inside the simulator, in world
    order; ``context(path)`` makes the context each is initialized with."""
    wanted = None if paths is None else set(paths)
    local = []
    for path, leaf in world.leaves.items():
        if wanted is not None and path not in wanted:
            continue
        comp = leaf.template(path, dict(leaf.params))
        try:
            comp.initialize(context(path))
        except NeedsSimulator:
            local.append(path)
        except Exception as exc:  # a template's own failure, reported as for a run
            raise ConfigError(
                f"initialize failed: {exc!r}", key=f"component {path} ({leaf.template.name()})"
            ) from None
    return local
