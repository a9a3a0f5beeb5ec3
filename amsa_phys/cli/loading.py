"""Load a file as a world or a scenario, whichever it is."""

from __future__ import annotations

from typing import Any

from ..model.scenario import Scenario, build_scenario
from ..model.world import WorldSpec, build_world
from ..model.yamlio import load_yaml


def load_any(path: str) -> tuple[str, Any]:
    """``("scenario", obj)`` if the file has a ``world:`` key, else ``("world", obj)``."""
    doc = load_yaml(path)
    if isinstance(doc.data, dict) and "world" in doc.data:
        scenario: Scenario = build_scenario(doc)
        return "scenario", scenario
    world: WorldSpec = build_world(doc.data, doc, ())
    return "world", world
