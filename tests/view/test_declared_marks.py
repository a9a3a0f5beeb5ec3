"""A user's template is drawn by what it declares (``Template.marks``), not by its name:
a fix of a template called anything shows as GPS crosses in the window's picture, and the
trajectory plot reads its columns."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.plots.trajectory import plotted_columns
from amsa_phys.runs.plotjob import plot_context
from amsa_phys.view.camera import Camera
from amsa_phys.view.draw import Renderer
from amsa_phys.view.pg import pygame
from amsa_phys.view.scene import Scene

#: a user's position sensor, named nothing the pictures know: it reports the rover 4 m
#: to its left, so its fixes are drawn where nothing else is
MODULE = '''
from amsa_phys.model.template import Kind, Port, Template
from amsa_phys.templatemarks import Fix


class Beacon(Template):
    """A fix 4 m left of what it measures."""

    kind = Kind.SENSOR
    inputs = (Port("trueX", 0.0, "x", "m"), Port("trueY", 0.0, "y", "m"))
    outputs = (Port("ex", 0.0, "x", "m"), Port("ey", 0.0, "y", "m"))
    uses_random = False
    marks = (Fix("ex", "ey", measures="trueX"),)

    def do_step(self, t, inp):
        return {"ex": inp["trueX"], "ey": inp["trueY"] + 4.0}


class Silent(Beacon):
    """The same sensor declaring nothing: nothing of it is drawn."""

    marks = ()
'''
WORLD = """\
name: beacon
components:
  Ctl: {template: ConstantPower, freq: 10, params: {left: 0, right: 0}}
  Norm: {template: NormalizePower, freq: 10,
         inputs: {powerL: Ctl.LeftPower, powerR: Ctl.RightPower}}
  Rover: {template: controlledRobot, freq: 10,
          inputs: {powerL: Norm.normalizedPowerL, powerR: Norm.normalizedPowerR}}
  Fixer:
    template: beaconmod_{tag}:{cls}
    freq: 4
    inputs: {trueX: Rover.posX, trueY: Rover.posY}
"""


def _scene(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, cls: str) -> Simulation:
    """The world with the user's template ``cls``, run 2 s (a module name per test: a
    module imported once stays imported)."""
    tag = f"{cls.lower()}_{abs(hash(tmp_path)) % 10**8}"
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / f"beaconmod_{tag}.py").write_text(MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    (tmp_path / "w.yaml").write_text(WORLD.replace("{tag}", tag).replace("{cls}", cls))
    (tmp_path / "s.yaml").write_text("world: w.yaml\nduration: 5\n")
    sim = Simulation.from_scenario(load_scenario(tmp_path / "s.yaml"))
    sim.initialize()
    return sim


def _drawn(sim: Simulation) -> tuple[Scene, pygame.Surface, Camera]:
    scene = Scene(sim)
    sim.advance(sim.grid.ticks(2))
    surface = pygame.Surface((320, 240))
    camera = Camera((320, 240), center=(0.0, 2.0))
    camera.mode = "free"
    Renderer((320, 240)).draw(surface, scene.frame(), camera)
    return scene, surface, camera


def _colour(surface: pygame.Surface, camera: Camera, x: float, y: float) -> tuple[int, ...]:
    px, py = camera.to_screen(x, y)
    return tuple(surface.get_at((int(px), int(py))))[:3]


def test_a_users_template_declaring_a_fix_is_drawn(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    scene, surface, camera = _drawn(_scene(tmp_path / "a", monkeypatch, "Beacon"))
    (track,) = scene.frame().gps
    assert (track.path, track.rover) == ("Fixer", "Rover")  # the fix takes the rover's colour
    x, y = track.fixes[-1]
    assert y == pytest.approx(4.0, abs=1e-6)
    marked = _colour(surface, camera, x, y)
    _, plain, plain_camera = _drawn(_scene(tmp_path / "b", monkeypatch, "Silent"))
    assert marked != _colour(plain, plain_camera, x, y)  # the cross is there, and only by marks


def test_the_trajectory_plot_reads_a_declared_fix(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    sim = _scene(tmp_path, monkeypatch, "Beacon")
    context = plot_context(sim.world)
    (link,) = context["gps"]
    assert (link["x"], link["y"], link["rover"]) == ("Fixer.ex", "Fixer.ey", "Rover")
    assert context["gps_of"] == {"Fixer": "Rover"}
    header = ["t", "Rover.posX", "Rover.posY", "Fixer.ex", "Fixer.ey"]
    assert {"Fixer.ex", "Fixer.ey"} <= plotted_columns(header, context["gps"])


RANGER = '''
from amsa_phys.physics.lidar import Lidar


class Ranger(Lidar):
    """A user's lidar under a name of its own: its scan mark comes with the class."""

    template_name = "Ranger"
'''
SCAN_WORLD = """\
name: ranger
physics:
  obstacles: [{type: box, x: 11, y: 0, width: 2, height: 30}]
components:
  Ctl: {template: ConstantPower, freq: 10, params: {left: 0, right: 0}}
  Norm: {template: NormalizePower, freq: 10,
         inputs: {powerL: Ctl.LeftPower, powerR: Ctl.RightPower}}
  Rover: {template: controlledRobot, freq: 10,
          inputs: {powerL: Norm.normalizedPowerL, powerR: Norm.normalizedPowerR}}
  Eyes:
    template: rangermod_{tag}:Ranger
    freq: 10
    params: {beams: 5, angle_min: -0.3, angle_max: 0.3, range_max: 15.0}
    inputs: {posX: Rover.posX, posY: Rover.posY, heading: Rover.heading}
"""


def test_a_users_scan_template_is_drawn_as_beams(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The wall 10 m ahead echoes on every beam of a lidar the pictures know by its mark."""
    tag = str(abs(hash(tmp_path)) % 10**8)
    (tmp_path / f"rangermod_{tag}.py").write_text(RANGER)
    monkeypatch.syspath_prepend(str(tmp_path))
    (tmp_path / "w.yaml").write_text(SCAN_WORLD.replace("{tag}", tag))
    (tmp_path / "s.yaml").write_text("world: w.yaml\nduration: 5\n")
    sim = Simulation.from_scenario(load_scenario(tmp_path / "s.yaml"))
    sim.initialize()
    scene, _, _ = _drawn(sim)
    (scan,) = scene.frame().scans
    assert scan.mount == "Rover"
    assert len(scan.ranges) == 5
    assert all(9.0 < r < 11.0 for r in scan.ranges)  # echoes off the wall, not range_max
    assert scan.range_max == 15.0
