"""The window's keys as a new user met them: zoom keeps the rover, ``c`` is the camera with the
signal list open, the help is never under the plot pane, and a ``points`` parameter is listed.

Pure logic where it can be (camera, picker, panel); the help's place against the pane on a
dummy SDL surface.
"""

from __future__ import annotations

import os
from pathlib import Path

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

import pygame
import pytest

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.view.camera import Camera
from amsa_phys.view.panel import ParamPanel
from amsa_phys.view.plotpane import (
    SignalPicker,
    beside_pane,
    pane_rect,
    picker_key,
    reaches_pane,
)

ROOT = Path(__file__).resolve().parents[2]
ROVERS = [(0.0, 0.0, "Leader"), (-15.0, 0.0, "Follower")]


def test_zooming_from_fit_follows_the_leader_and_keeps_it_centred() -> None:
    cam = Camera((800, 600))
    cam.update(ROVERS, 0.0)  # fit: both rovers in the picture
    label = cam.key_zoom(1.25, ["Leader", "Follower"])
    assert label == "follow Leader"
    for _ in range(8):  # zoomed well in: the fit would have lost one of them
        cam.key_zoom(1.25, ["Leader", "Follower"])
    moved = [(x + 30.0, y + 4.0, n) for x, y, n in ROVERS]  # the leader drove on
    cam.update(moved, 0.05)
    px, py = cam.to_screen(30.0, 4.0)
    assert (round(px), round(py)) == (round(cam.mid_x), round(cam.mid_y))


def test_zoom_after_a_pan_stays_free() -> None:
    cam = Camera((800, 600))
    cam.update(ROVERS, 0.0)
    cam.pan(100, 0)
    assert cam.key_zoom(1.25, ["Leader"]) == "free"


def test_c_is_the_cameras_key_with_the_signal_list_open() -> None:
    picker = SignalPicker(["t", "FollowerCompass.compassHeading", "Leader.posX"])
    picker.visible = True
    assert not picker_key(picker, pygame.K_c, "c")  # the window's: camera
    assert picker.filter == ""
    assert picker_key(picker, 0, "/")  # / starts a filter, then letters filter
    for ch in "compass":
        assert picker_key(picker, 0, ch)
    assert picker.matches == ["FollowerCompass.compassHeading"]
    assert picker_key(picker, pygame.K_ESCAPE, "\x1b")  # ends the filter, list stays
    assert picker.visible
    assert not picker.filtering
    assert not picker_key(picker, pygame.K_z, "z")


def test_the_help_and_the_list_keep_clear_of_the_plot_pane() -> None:
    pygame.display.init()
    try:
        screen = pygame.Surface((1000, 700))
        picker = SignalPicker(["t", "a"])
        picker.picked = ["a"]
        pane = pane_rect(screen.get_rect(), picker)
        assert pane is not None
        margin, width = beside_pane(screen, pane, 40, 30, 18)  # 30 lines reach the pane
        assert screen.get_width() - margin <= pane.left  # its right edge left of the pane
        assert width is not None
        assert width <= pane.left - 10  # and it wraps within the room left of it
        assert beside_pane(screen, pane, 40, 3, 18) == (10, None)  # short: as before
        assert beside_pane(screen, None, 40, 30, 18) == (10, None)
        assert reaches_pane(pane, 40, 30, 18)  # the help of 30 lines goes at the left
        assert not reaches_pane(pane, 40, 3, 18)
        assert not reaches_pane(None, 40, 30, 18)
    finally:
        pygame.display.quit()


@pytest.fixture(scope="module")
def panel() -> ParamPanel:
    sim = Simulation.from_scenario(load_scenario(ROOT / "scenarios" / "scenario1.yaml"))
    sim.initialize()
    return ParamPanel(sim)


def test_a_points_parameter_is_listed_with_its_value(panel: ParamPanel) -> None:
    keys = [r.key for r in panel.rows]
    assert "Leader.waypoints" in keys
    panel.index = keys.index("Leader.waypoints")
    (line,) = [x for x in panel.lines(40) if "Leader.waypoints" in x]
    assert "[0 points]" in line
    assert "set it in the scenario" in line


def test_a_points_parameter_is_not_edited_here(panel: ParamPanel) -> None:
    panel.index = [r.key for r in panel.rows].index("Leader.waypoints")
    panel.step(1)
    panel.type_char("3")
    assert panel.commit() is None
    assert panel.refused
    assert "set it in the scenario" in panel.message
