"""Load a file as a world or a scenario, whichever it is."""

from __future__ import annotations

from typing import Any

from ..model.scenario import Scenario, build_scenario
from ..model.world import WorldSpec, build_world
from ..model.yamlio import load_yaml

#: Keys only a scenario has: a file with one of them and no ``components:`` is a scenario
#: whose ``world:`` is missing or misspelt (``wrld:``), not a world with odd keys.
SCENARIO_ONLY = frozenset(
    {
        "world",
        "duration",
        "seed",
        "timeline",
        "quality",
        "expect",
        "set",
        "sweep",
        "log_rate",
        "trace_columns",
    }
)


def load_any(path: str) -> tuple[str, Any]:
    """``("scenario", obj)`` if the file has a ``world:`` key, or scenario keys and no
    ``components:``; else ``("world", obj)``."""
    doc = load_yaml(path)
    data = doc.data
    if isinstance(data, dict) and (
        "world" in data or ("components" not in data and SCENARIO_ONLY & set(map(str, data)))
    ):
        scenario: Scenario = build_scenario(doc)
        return "scenario", scenario
    world: WorldSpec = build_world(doc.data, doc, ())
    return "world", world
