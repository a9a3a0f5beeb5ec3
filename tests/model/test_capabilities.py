"""Batch capabilities are what templates declare (issue 32 item 5), not their names."""

from __future__ import annotations

import dataclasses
from fractions import Fraction
from pathlib import Path
from typing import Any

import toys

from amsa_phys.model.scenario import Change, Phase, Timeline, load_scenario
from amsa_phys.model.world import with_leaf
from amsa_phys.physics.templates import ControlledRobot, FreeRobot
from amsa_phys.runs.batched import unbatchable

SCENARIO = """
world:
  components:
    A: {template: freeRobot, freq: 10}
    R: {template: "toys:Relay", freq: 10, inputs: {x: A.posX}}
duration: 2
"""


class Declared(toys.Relay):
    """A user template without step_many that says a batch may hold it."""

    template_name = "declaredRelay"
    batchable = True


class Zone(toys.Relay):
    template_name = "zoneRelay"
    batchable = True
    shares_physics = False


class Fixed(toys.Relay):
    template_name = "fixedRelay"
    batchable = True
    batch_params_at_start = True


def _scenario(tmp_path: Path, template: type, change_later: bool = False) -> Any:
    path = tmp_path / "s.yaml"
    path.write_text(SCENARIO)
    sc = load_scenario(path)
    leaf = dataclasses.replace(sc.world.leaves["R"], template=template)
    phases = list(sc.timeline.phases)
    if change_later:
        phases.append(Phase(Fraction(1), [Change("R", "anything", 1.0)]))
    timeline = Timeline.of(phases, sc.duration)
    return dataclasses.replace(sc, world=with_leaf(sc.world, leaf), timeline=timeline)


def test_a_user_template_is_refused_unless_it_declares_itself_batchable(tmp_path: Path) -> None:
    assert "R is a user template (Relay) without step_many" in str(
        unbatchable(_scenario(tmp_path, toys.Relay))
    )
    assert unbatchable(_scenario(tmp_path, Declared)) is None


def test_shares_physics_and_params_at_start_are_read_from_the_template(tmp_path: Path) -> None:
    assert "terrain zone" in str(unbatchable(_scenario(tmp_path, Zone)))
    assert unbatchable(_scenario(tmp_path, Fixed)) is None  # no change during the run
    why = unbatchable(_scenario(tmp_path, Fixed, change_later=True))
    assert why == "the timeline changes R.anything during the run"
    assert unbatchable(_scenario(tmp_path, Declared, change_later=True)) is None


def test_the_robots_say_when_they_are_random() -> None:
    """``sweep`` once named the robots to know this; they declare it now (``is_random``),
    so a grid point with a random leader is not reported as giving every seed one run."""
    assert [FreeRobot.is_random({"behavior": b}) for b in (1, 2, 3, 4, 5)] == [
        False,
        False,
        False,
        True,
        False,
    ]
    assert not ControlledRobot.is_random({})


def test_batchable_is_never_inferred_from_the_module_a_template_lives_in(tmp_path: Path) -> None:
    """A template in a module named like the package's own, declaring nothing and without
    step_many, runs alone like any user template; every built-in template declares itself."""
    import importlib

    from amsa_phys.model.template import BUILTINS

    posing = type("Posing", (toys.Relay,), {"template_name": "posing", "__module__": "amsa_phys.x"})
    assert "without step_many" in str(unbatchable(_scenario(tmp_path, posing)))
    for name, ref in BUILTINS.items():
        module, _, cls = ref.partition(":")
        template = getattr(importlib.import_module(module), cls)
        assert template.batchable is not None or hasattr(template, "step_many"), name
