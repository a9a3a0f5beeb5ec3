"""A physics world let go at its run's end, so reference counting frees the run.

A world and its pymunk Space hold each other: the Space's collision handlers are the world's
own methods, and the world holds the Space and the run (``sim``). The rovers read their state
through the force model's methods, and the model holds the rovers; the rovers and the
pending commands hold each other by the world's list of rovers. Left like that, an ended
run waits for the cyclic garbage collector, and a Gymnasium env that resets every few
hundred steps keeps it walking each ended episode (``Simulation.release`` in
``engine/runner.py``, which calls :func:`release_world` through the world's
``release_run``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any


def release_world(world: Any, pairs: Sequence[tuple[int, int]]) -> None:
    """Break ``world``'s cycles (see the module docstring): its Space's handlers for the
    collision-type ``pairs`` it registered call nothing of it, its rovers read no state of
    the force model, and its list of rovers goes empty. The handlers stay callable: pymunk
    calls ``separate`` for the pairs still touching when it frees the Space."""
    for a, b in pairs:
        world.space.on_collision(a, b, begin=_released, separate=_released)
    for rover in world.rovers:
        rover.attach_state(_no_state)
        rover.attach_rims(_no_state)
    world.rovers.clear()


def _released(_arbiter: Any, _space: Any, _data: Any) -> None:
    """A released world's collision handler."""


def _no_state() -> Any:
    """A released world's rovers' state reader."""
    raise RuntimeError("the run was released: its rovers have no state")
