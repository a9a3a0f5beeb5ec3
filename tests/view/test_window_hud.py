"""The window's HUD and panels say what the run is doing, readably (issue 30's list)."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.palette import ALERT
from amsa_phys.view.pg import pygame
from amsa_phys.view.window import Window

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"


def press(key: int, text: str = "", mod: int = 0) -> None:
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key, mod=mod, unicode=text))


def window(overrides: list[str] | None = None, duration: float = 20) -> Window:
    scenario = load_scenario(SCENARIO, overrides, duration=duration)
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    return Window(sim, scenario.quality, size=(800, 450), planned=scenario.timeline.planned)


def test_a_parameter_set_twice_is_listed_once_with_the_value_in_force() -> None:
    w = window(["MyFollowerController.Kv=0.5"])
    w.frame(0.0)
    text = w.scene.frame().phase_text
    assert text.count("Kv=") == 1
    assert "Kv=0.5" in text


def test_a_shortened_run_counts_the_files_phases_and_says_where_it_stops() -> None:
    w = window(duration=100)  # the file has a second phase at 125 s
    w.frame(0.0)
    assert w.scene.frame().phase_text == (
        "phase 0 (of 0–1) from 0 s: behavior=1, lostDataGPS=0, motorCoef=100, Kv=0.35"
        " (run stops at 100 s of 500)"
    )


def open_panel_on(w: Window, key: str) -> None:
    press(pygame.K_p)
    w.frame(0.0)
    for _ in range(len(w.panel.rows)):
        if w.panel.row.key == key:
            return
        press(pygame.K_DOWN)
        w.frame(0.0)
    raise AssertionError(key)


def test_a_refused_value_is_in_the_alert_colour_not_faint_grey() -> None:
    w = window()
    open_panel_on(w, "MyFollowerController.Kv")
    for ch in "abc":  # letters are not typed in; Enter with nothing typed is refused
        press(ord(ch), ch)
    press(pygame.K_RETURN)
    w.frame(0.0)
    assert w.panel.refused
    assert w.panel.message.startswith("change the value first")
    red = sum(
        1
        for x in range(0, w.screen.get_width() // 2)
        for y in range(w.screen.get_height())
        if tuple(w.screen.get_at((x, y)))[:3] == ALERT
    )
    assert red > 20  # the message's glyphs
    # a value that is applied is confirmed in ink, not as a refusal
    for ch in "0.2":
        press(pygame.K_PERIOD if ch == "." else ord(ch), ch)
    press(pygame.K_RETURN)
    w.frame(0.0)
    assert not w.panel.refused


@pytest.mark.parametrize("size", [(800, 450), (1280, 720)])
def test_the_open_panel_does_not_cover_the_rovers(size: tuple[int, int]) -> None:
    scenario = load_scenario(SCENARIO, duration=20)
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    w = Window(sim, scenario.quality, size=size)
    for _ in range(20):
        w.frame(0.1)
    press(pygame.K_p)
    for _ in range(40):  # the camera glides to the room beside the panel
        w.frame(0.1)
    left = w.camera.left
    assert left > 100
    for r in w.scene.rovers():
        x, y = w.camera.to_screen(r.x, r.y)
        assert left < x < size[0], r.name
        assert 0 < y < size[1], r.name
    press(pygame.K_p)  # closed: the whole window again
    w.frame(0.1)
    assert w.camera.left == 0


def test_the_live_plot_pane_samples_a_picked_signal_while_running() -> None:
    w = window()
    press(pygame.K_g)
    press(0, "/")  # letters filter after /: without it they are the window's keys
    for ch in "compass":
        press(0, ch)
    press(pygame.K_RETURN)
    press(pygame.K_g)
    w.frame(0.0)
    assert w.picker.picked == ["FollowerCompass.compassHeading"]
    for _ in range(20):  # two simulated seconds at x1
        w.frame(0.1)
    t, v = w.series.series("FollowerCompass.compassHeading", 30.0)
    assert len(t) == 41  # every logged instant (20 Hz, 0 to 2 s) since it was picked
    assert t[0] == 0.0
    assert t[-1] == pytest.approx(float(w.sim.now))
    assert v[-1] == w.sim.values["FollowerCompass.compassHeading"]


def test_the_snapshot_and_video_hud_count_phases_like_the_window(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--duration`` with ``--snapshot``: the still's HUD says what the window's says."""
    from amsa_phys.cli.main import main
    from amsa_phys.view import video as recorder

    seen: list[str] = []

    class Seen(recorder.Snapshot):
        def capture(self) -> None:
            seen.append(self.scene.frame().phase_text)
            super().capture()

    monkeypatch.setattr(recorder, "Snapshot", Seen)
    png = tmp_path / "still.png"
    argv = ["run", str(SCENARIO), "--headless", "--duration", "100", "-q", "--no-plot"]
    assert (
        main([*argv, "--snapshot", str(png), "--snapshot-at", "1", "--out", str(tmp_path / "r")])
        == 0
    )
    assert png.is_file()
    assert seen == [
        "phase 0 (of 0–1) from 0 s: behavior=1, lostDataGPS=0, motorCoef=100, Kv=0.35"
        " (run stops at 100 s of 500)"
    ]


def live_change_at(size: tuple[int, int]) -> Window:
    """scenario1 for 9.4 s at x1, then Kv = 0.2 applied in the panel (``live at 9.4 s``),
    the panel closed again."""
    scenario = load_scenario(ROOT / "scenarios" / "scenario1.yaml")
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    w = Window(sim, scenario.quality, size=size)
    for _ in range(94):
        w.frame(0.1)
    open_panel_on(w, "MyFollowerController.Kv")
    for ch in "0.2":
        press(pygame.K_PERIOD if ch == "." else ord(ch), ch)
    press(pygame.K_RETURN)
    w.frame(0.1)
    press(pygame.K_p)
    for _ in range(5):
        w.frame(0.1)
    return w


def covered(w: Window) -> list[tuple[str, str]]:
    """(rover, box) for every rover whose centre is under a box drawn over the map."""
    boxes = dict(w.renderer.boxes)
    out = []
    for r in w.scene.rovers():
        at = w.camera.to_screen(r.x, r.y)
        out += [(r.name, name) for name, box in boxes.items() if box.collidepoint(at)]
    return out


@pytest.mark.parametrize("size", [(1280, 720), (320, 240)], ids=["1280x720", "smallest"])
def test_the_hud_keeps_a_live_change_on_one_line(size: tuple[int, int]) -> None:
    """``Kv=0.2 live at 9.4 s`` lost its ``s`` to a second line at 1280x720 (the status box
    held the long notice and squeezed the HUD). At 1280x720 the whole phase line fits on
    one line; in the smallest window (320x240, what a resize allows) it wraps between items,
    never inside one; the boxes stay inside the window, apart, and off the rovers."""
    w = live_change_at(size)
    phase = w.scene.frame().phase_text
    assert phase.endswith("Kv=0.2 live at 9.4 s")
    hud = w.renderer.texts["hud"]
    if size == (1280, 720):
        assert phase in hud
    else:
        assert any(line.endswith("Kv=0.2 live at 9.4 s") for line in hud), hud
    assert any("live: MyFollowerController.Kv = 0.2" in line for line in hud)  # the notice
    screen = w.screen.get_rect()
    assert all(screen.contains(box) for box in w.renderer.boxes.values())
    assert not w.renderer.boxes["hud"].colliderect(w.renderer.boxes["status"])
    assert covered(w) == []


@pytest.mark.parametrize("size", [(1280, 720), (800, 450)], ids=str)
def test_the_help_does_not_hide_the_rovers_and_any_key_puts_it_away(
    size: tuple[int, int],
) -> None:
    """The key list covered the leader: the camera now frames the rovers beside it (and
    under the HUD). Esc closes it without quitting; any other key closes it and acts."""
    scenario = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=30)
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    w = Window(sim, scenario.quality, size=size)
    for _ in range(60):
        w.frame(0.1)
    press(pygame.K_h)
    w.frame(0.1)  # the frame the help opens in already frames the rovers beside it
    assert w.show_help
    helpbox = pygame.Rect(size[0] - w.camera.right, 0, w.camera.right, size[1])
    assert w.camera.right > size[0] // 4
    for r in w.scene.rovers():
        x, y = w.camera.to_screen(r.x, r.y)
        assert 0 < x < helpbox.left, r.name
        assert 0 < y < size[1], r.name
    assert covered(w) == []
    press(pygame.K_ESCAPE)
    w.frame(0.1)
    assert not w.show_help
    assert w.running  # Esc put the help away, it did not quit
    assert w.camera.right == 0
    press(pygame.K_h)
    press(pygame.K_SPACE)  # any other key: the help goes and the key does its job
    w.frame(0.1)
    assert not w.show_help
    assert w.paused
