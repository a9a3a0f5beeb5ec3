"""A scenario file: a world plus a timed sequence of parameter changes (the paper's 2.1).

Each timeline entry starts a new phase; phase 0 starts at t = 0 with the ``set`` values.
Every value is judged by the parameter's own ``Param.coerce``, with file, line and key.

This module is the entry point others import; the concepts live in rooms of their own:
parameter changes and settings (``changes.py``), the phases and their flattening
(``timeline.py``), the Scenario as data (``scenariospec.py``), building it from a file
(``scenariobuild.py``), configuring it with options (``configure.py``) and the metrics an
``expect`` names (``metrics.py``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from .changes import (
    PHYSICS_PREFIX,
    WHOLE_RUN_KEYS,
    Change,
    is_frequency,
    parse_physics_override,
    parse_setting,
    physics_setting,
    resolve_change,
    set_changes,
    set_frequency,
    with_physics,
)
from .configure import configure_scenario
from .metrics import METRICS
from .scenariobuild import build_scenario, check_phases, written_values
from .scenariospec import (
    DEFAULT_LOG_RATE_HZ,
    DEFAULT_TOLERANCE,
    Expectation,
    Quality,
    Scenario,
    shortened,
    traced_columns,
    without_adapt,
)
from .timeline import Phase, Step, Timeline
from .world import WorldSpec
from .yamlio import load_yaml

__all__ = [
    "DEFAULT_LOG_RATE_HZ",
    "DEFAULT_TOLERANCE",
    "METRICS",
    "PHYSICS_PREFIX",
    "WHOLE_RUN_KEYS",
    "Change",
    "Expectation",
    "Phase",
    "Quality",
    "Scenario",
    "Step",
    "Timeline",
    "build_scenario",
    "check_phases",
    "configure_scenario",
    "is_frequency",
    "load_scenario",
    "parse_override",
    "parse_physics_override",
    "parse_setting",
    "physics_setting",
    "resolve_change",
    "set_changes",
    "set_frequency",
    "shortened",
    "traced_columns",
    "with_physics",
    "without_adapt",
    "written_values",
]


def load_scenario(
    path: str | Path,
    overrides: list[str] | None = None,
    seed: int | None = None,
    duration: float | None = None,
    log_rate: float | None = None,
    trace_columns: str | Sequence[str] | None = None,
) -> Scenario:
    """Load a scenario; command-line overrides are judged like file values."""
    return configure_scenario(load_yaml(path), overrides, seed, duration, log_rate, trace_columns)


def parse_override(text: str, world: WorldSpec) -> Change | None:
    """``Comp.param=V`` as a Change; a Leaf's frequency or timing is refused here, since it
    changes the world: :func:`parse_setting` returns the new world with it."""
    change, new_world = parse_setting(text, world)
    if new_world is not world:
        raise ValueError(f"{text!r} sets the world; use parse_setting")
    return change
