"""``h`` while the signal list is open shows the help, at the left (the list holds the right),
in ``view`` and in the live window: it used to toggle a help nobody saw, which then appeared
when the list was closed."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.cli.view import load_run
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.view.pg import pygame
from amsa_phys.view.player import Player
from amsa_phys.view.window import Window

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"
SIZE = (1280, 720)


def press(key: int, text: str = "") -> None:
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key, mod=0, unicode=text))


def _rovers_beside(camera: object, rovers: list[object], left: int) -> None:
    for r in rovers:
        x, _y = camera.to_screen(r.x, r.y)  # type: ignore[attr-defined]
        assert x > left, r.name  # type: ignore[attr-defined]


@pytest.fixture(scope="module")
def rundir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("help") / "run"
    argv = ["run", str(SCENARIO), "--headless", "--duration", "20", "--no-plot", "-q"]
    assert main([*argv, "--out", str(out)]) == 0
    return out


def test_view_draws_the_help_at_the_left_while_the_list_is_open(rundir: Path) -> None:
    player = Player(load_run(rundir), title="test", size=SIZE)
    player.frame(0.0)
    press(pygame.K_g)
    player.frame(0.0)
    assert player.picker.visible
    assert player.camera.left == 0  # the list alone: nothing at the left
    press(pygame.K_h)
    player.frame(0.0)
    assert player.picker.visible
    assert player.show_help
    assert player.camera.left > SIZE[0] // 5  # the help's box, drawn at the left
    assert player.camera.right > 0  # and the list still at the right
    frame = player.scene.frame(player.row)
    _rovers_beside(player.camera, list(frame.rovers), player.camera.left)
    press(pygame.K_h)  # h again puts it away, the list stays
    player.frame(0.0)
    assert player.picker.visible
    assert not player.show_help
    assert player.camera.left == 0


def test_the_live_window_draws_the_help_at_the_left_while_the_list_is_open() -> None:
    scenario = load_scenario(SCENARIO, duration=20)
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    w = Window(sim, scenario.quality, size=SIZE)
    for _ in range(10):
        w.frame(0.1)
    press(pygame.K_g)
    w.frame(0.1)
    assert w.picker.visible
    assert w.camera.left == 0
    press(pygame.K_h)
    w.frame(0.1)
    assert w.picker.visible
    assert w.show_help
    assert w.camera.left > SIZE[0] // 5
    assert w.camera.right > 0
    _rovers_beside(w.camera, list(w.scene.rovers()), w.camera.left)
