"""A user's ground template is plotted by its declared zone mark, whatever its name: the
trajectory plot of a run fills and names it, with the timeline's change in its label."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from amsa_phys.cli.main import main
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.physics.terrain import zone_colours
from amsa_phys.runs.plotjob import plot_context
from amsa_phys.view.pg import pygame

MODULE = '''
from amsa_phys.physics.zones import FrictionZone


class Puddle(FrictionZone):
    """A user's patch of ground under a name of its own (its zone mark comes with it)."""

    template_name = "Puddle"
'''
WORLD = """\
name: puddles
components:
  Wet:
    template: puddlemod_{tag}:Puddle
    freq: 1
    params: {friction: 0.8, rollingResistance: 0.02, polygon: [[5, -3], [15, -3], [15, 3], [5, 3]]}
  Ctl: {template: ConstantPower, freq: 10, params: {left: 100, right: 100}}
  Norm: {template: NormalizePower, freq: 10,
         inputs: {powerL: Ctl.LeftPower, powerR: Ctl.RightPower}}
  Rover: {template: controlledRobot, freq: 10,
          inputs: {powerL: Norm.normalizedPowerL, powerR: Norm.normalizedPowerR}}
"""
SCENARIO = """\
world: w.yaml
duration: 6
timeline:
  - {at: 2, set: {Wet.friction: 0.1}}
"""


@pytest.fixture
def scenario(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    tag = str(abs(hash(tmp_path)) % 10**8)
    (tmp_path / f"puddlemod_{tag}.py").write_text(MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    (tmp_path / "w.yaml").write_text(WORLD.replace("{tag}", tag))
    (tmp_path / "s.yaml").write_text(SCENARIO)
    return tmp_path / "s.yaml"


def test_a_users_zone_template_is_plotted_by_its_mark(scenario: Path, tmp_path: Path) -> None:
    out = tmp_path / "run"
    assert main(["run", str(scenario), "--headless", "-q", "--out", str(out)]) == 0
    image = pygame.image.load(str(out / "trajectory.png"))
    pixels = pygame.surfarray.array3d(image).reshape(-1, 3)
    fill = np.array(zone_colours(0.8, 0.02, (255, 255, 255))[0])
    assert (np.abs(pixels - fill).sum(axis=1) <= 3).sum() > 5000  # a filled rectangle


def test_the_plot_context_names_the_zone_and_its_change(scenario: Path) -> None:
    loaded = load_scenario(scenario)
    sim = Simulation.from_scenario(loaded)
    resolved = {
        "world": {
            "components": {
                "Wet": {"template": "Puddle", "params": loaded.world.leaves["Wet"].params}
            }
        },
        "timeline": [{"at": 2, "set": {"Wet.friction": 0.1}}],
    }
    (zone,) = plot_context(sim.world, resolved)["zones"]
    assert zone.name == "Wet"
    assert zone.label == "Wet: μ 0.8, Crr 0.02; from 2 s μ 0.1"
