"""Judging ``ros2:`` / ``--ros2``: which Leaves a user's ROS 2 nodes step.

No ROS: the loader refuses a bad list in one line (file, line, key) before anything starts.
Besides the names, the Leaves named are initialized once (``placement.classify``) to refuse
one that shares the physics world: a node cannot step a body. What each external Leaf's
topics are is ``ros/external.py``'s.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import ConfigError
from .placement import AloneContext, classify
from .rosnames import BASE, RESERVED
from .suggest import did_you_mean
from .world import WorldSpec


def parse_list(raw: object, key: str) -> tuple[str, ...]:
    """``"A,B"`` or ``["A", "B"]`` -> ``("A", "B")`` (``--ros2`` and ``ros2:``)."""
    if isinstance(raw, str):
        items = [s.strip() for s in raw.split(",")]
    elif isinstance(raw, (list, tuple)) and all(isinstance(s, str) for s in raw):
        items = [s.strip() for s in raw]
    else:
        raise ConfigError("expected Leaf names: a comma-separated string or a list", key=key)
    if not items or any(not s for s in items):
        raise ConfigError("an empty Leaf name", key=key)
    seen: list[str] = []
    for s in items:
        if s not in seen:
            seen.append(s)
    return tuple(seen)


def problem(world: WorldSpec, paths: Sequence[str]) -> str | None:
    """Why ``paths`` cannot be external Leaves of ``world`` (one sentence), or None."""
    for path in paths:
        if path not in world.leaves:
            return f"{path!r} is not a Leaf of the world" + did_you_mean(path, world.leaves)
        for part in path.split("."):
            if not BASE.match(part):
                return (
                    f"{part!r} (in {path}) is not a valid ROS name "
                    "(a letter, then letters, digits, _)"
                )
        if path.split(".")[0] in RESERVED:
            return f"{path.split('.')[0]!r} is a name amsa-phys uses on the ROS graph itself"
        leaf = world.leaves[path]
        for p in (*leaf.template.outputs, *leaf.template.params):
            if not BASE.match(p.name):
                return f"{p.name!r} of {path} is not a valid ROS name"
        for port, buffer in leaf.inputs.items():
            source = producer(world, buffer)
            if source in paths and source != path:
                return (
                    f"{path}.{port} reads {buffer}, an output of {source}, also external: "
                    "wire the two nodes to each other in ROS, or keep one of them in amsa-phys"
                )
    bodies = classify(
        world, lambda path: AloneContext(path, world, np.random.default_rng(0)), paths
    )
    if bodies:
        body = bodies[0]
        # what a user means by "my robot's controller": the Leaves feeding the body
        feeds = sorted(
            {
                source
                for buffer in world.leaves[body].inputs.values()
                if (source := producer(world, buffer)) in world.leaves and source != body
            }
        )
        hint = f" (its commands come from {', '.join(feeds)})" if feeds else ""
        return (
            f"{body} shares the simulator's physics world (a body, a ray-cast sensor), "
            "so it stays in amsa-phys: a ROS 2 node can step a Leaf that only exchanges Data"
            f"{hint}"
        )
    return None


def producer(world: WorldSpec, buffer: str) -> str:
    """The Leaf that publishes ``buffer`` (an array port by its name too)."""
    if buffer in world.buffers:
        return world.buffers[buffer].producer
    return buffer.rpartition(".")[0]  # an array port by its name
