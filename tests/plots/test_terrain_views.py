"""Terrain zones as a user sees them: in the window's and the video's picture, in the
trajectory plot, in ``describe``, and refused when their polygon is not one."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from amsa_phys.cli.main import main
from amsa_phys.engine.runner import Simulation
from amsa_phys.errors import ConfigError
from amsa_phys.model.scenario import load_scenario
from amsa_phys.model.world import load_world
from amsa_phys.physics.terrain import zone_colours
from amsa_phys.plots.zones import zones_of
from amsa_phys.runs.rundata import read_run, timeline_of
from amsa_phys.templatemarks import Zone, marked
from amsa_phys.view.camera import Camera
from amsa_phys.view.draw import BACKGROUND, Renderer
from amsa_phys.view.pg import pygame
from amsa_phys.view.scene import Scene

WORLD = (Path(__file__).resolve().parents[1] / "fixtures" / "mud_track_world.yaml").read_text()
SCENARIO = """\
world: w.yaml
duration: 12
timeline:
  - {at: 2, set: {Mud.friction: 0.1, Mud.rollingResistance: 0.3}, label: ice}
"""


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    (tmp_path / "w.yaml").write_text(WORLD)
    (tmp_path / "s.yaml").write_text(SCENARIO)
    return tmp_path / "s.yaml"


def zone_pixel(sim: Simulation) -> tuple[int, int, int]:
    """The colour drawn at a point inside the zone, away from its label and the rover."""
    surface = pygame.Surface((320, 240))
    camera = Camera((320, 240), center=(10.0, 0.0))
    camera.mode = "free"
    Renderer((320, 240)).draw(surface, Scene(sim).frame(), camera)
    px, py = camera.to_screen(13.0, -2.0)
    return tuple(surface.get_at((int(px), int(py))))[:3]  # type: ignore[return-value]


def test_the_picture_shows_the_zone_as_it_is_now(scenario: Path) -> None:
    sim = Simulation.from_scenario(load_scenario(scenario))
    sim.initialize()
    sim.advance(sim.grid.ticks(1))
    assert zone_pixel(sim) == zone_colours(0.8, 0.02, BACKGROUND)[0]  # firm ground: brown
    sim.advance(sim.grid.ticks(3))
    assert zone_pixel(sim) == zone_colours(0.1, 0.3, BACKGROUND)[0]  # iced over: blue
    assert zone_colours(0.1, 0.3, BACKGROUND)[0] != zone_colours(0.8, 0.02, BACKGROUND)[0]


def test_the_trajectory_plot_draws_and_names_the_zone(scenario: Path, tmp_path: Path) -> None:
    out = tmp_path / "run"
    assert main(["run", str(scenario), "--headless", "-q", "--out", str(out)]) == 0
    run = read_run(out)
    assert run.world is not None
    declared = {path: mark for path, _, mark in marked(run.world.leaves, Zone)}
    params = {path: run.world.leaves[path].params for path in declared}
    (zone,) = zones_of(params, declared, timeline_of(run.resolved))
    assert zone.name == "Mud"
    assert zone.polygon == ((5.0, -3.0), (15.0, -3.0), (15.0, 3.0), (5.0, 3.0))
    assert zone.label == "Mud: μ 0.8, Crr 0.02; from 2 s μ 0.1, Crr 0.3"
    image = pygame.image.load(str(out / "trajectory.png"))
    pixels = pygame.surfarray.array3d(image).reshape(-1, 3)
    fill = np.array(zone_colours(0.8, 0.02, (255, 255, 255))[0])
    assert (np.abs(pixels - fill).sum(axis=1) <= 3).sum() > 5000  # a filled rectangle


def test_describe_lists_the_zone_and_its_ranges(
    scenario: Path, capsys: pytest.CaptureFixture
) -> None:
    assert main(["describe", str(scenario)]) == 0
    text = capsys.readouterr().out
    assert "Mud: frictionZone (environment) at 1 Hz" in text
    assert "friction = 0.8  [0, 5]" in text
    assert "rollingResistance = 0.02  [0, 1]" in text


@pytest.mark.parametrize(
    ("polygon", "message"),
    [
        ("[[0, 0], [1, 0]]", "polygon needs at least 3 corners, got 2"),
        ("[[0, 0], [1, 1], [2, 2]]", "polygon has no area (its corners are on one line)"),
    ],
    ids=["two corners", "on a line"],
)
def test_a_zone_that_is_not_a_polygon_is_refused_with_its_line(
    tmp_path: Path, polygon: str, message: str
) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(
        f"components:\n  Mud: {{template: frictionZone, params: {{polygon: {polygon}}}}}\n"
    )
    with pytest.raises(ConfigError) as exc:
        load_world(path)
    assert str(exc.value) == f"{path}:2: components.Mud.params: {message}"
