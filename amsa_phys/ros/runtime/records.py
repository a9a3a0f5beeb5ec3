"""What a ROS run records: the values it actually used, and the length it actually ran.

The launch loads ``config/NAME_params.yaml`` onto the parameter server and every node reads
its parameters from there, so a user who edits that file (or sets a parameter before the
run) changes the run. :func:`fold_server_values` writes such values into the scenario's
phase 0, as a ``set:`` in the file would be: the engine applies them at t = 0 and the run's
``scenario.yaml`` records them, so it replays the run (it recorded the file's old
value). :func:`cut` is ``duration:=S``, the same cut as ``amsa-phys run --duration S``.
"""

from __future__ import annotations

import math
from dataclasses import replace
from fractions import Fraction
from typing import Any

from ...errors import ConfigError
from ...model.scenario import Change, Scenario, shortened
from . import rosio


def start_values(scenario: Scenario) -> dict[tuple[str, str], Any]:
    """Every Leaf parameter at t = 0: the world's values with the scenario's ``set:``."""
    values = {
        (path, name): value
        for path, leaf in scenario.world.leaves.items()
        for name, value in leaf.params.items()
    }
    for change in scenario.timeline.initial:
        values[(change.leaf, change.param)] = change.value
    return values


def fold_server_values(rospy: Any, scenario: Scenario) -> tuple[Scenario, list[Change]]:
    """Make the parameter server's values at the start the scenario's phase-0 values.

    Each value is judged as a file value is (type, range, rules between parameters). Returns
    the scenario to run (a new one: Scenario is frozen) and the changes made (none when
    nobody edited anything: the run is then the file's, byte for byte).
    """
    start = start_values(scenario)
    changes = list(scenario.timeline.initial)
    folded = []
    for path, leaf in scenario.world.leaves.items():
        for name, value in rosio.read_params(rospy, leaf).items():
            old = start.get((path, name))
            if _same(value, old):
                continue
            change = Change(path, name, value)
            changes = [c for c in changes if c.key != change.key] + [change]
            folded.append(change)
    if not folded:
        return scenario, folded
    return replace(scenario, timeline=scenario.timeline.with_start(changes)), folded


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return type(a) is type(b) and a == b


def cut(scenario: Scenario, text: str) -> Scenario:
    """``duration:=S``: what ``amsa-phys run --duration S`` does (``model.scenario.shortened``):
    the run stops at S, later changes drop out, the phase it stops in is partial."""
    try:
        seconds = float(text)
    except ValueError:
        raise ConfigError(f"expected seconds, got {text!r}", key="duration:=") from None
    if not seconds > 0 or math.isinf(seconds):
        raise ConfigError(f"must be a positive finite number, got {text}", key="duration:=")
    return shortened(scenario, Fraction(str(seconds)))
