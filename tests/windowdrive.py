"""Driving the interactive window from a test: scripted keys on an exact clock.

``run_scenario(..., window=driver)`` hands a driver the Simulation and the scenario; a
driver built here makes a live change through the parameter panel, as a user would, so a
test can compare the session with its replay (in process, or under ROS).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from amsa_phys.view.pg import pygame
from amsa_phys.view.window import Window

Driver = Callable[[Any, Any, Any], None]


def press(key: int, text: str = "", mod: int = 0) -> None:
    """One key pressed (and typed as ``text``)."""
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key, mod=mod, unicode=text))


def live_change(key: str, value: str, at: float, faster: int = 0) -> Driver:
    """A session that runs to ``at`` s, sets ``key`` to ``value`` in the parameter panel,
    closes it, presses ``]`` ``faster`` times (each doubles the speed) and runs to the end."""

    def drive(sim: Any, scenario: Any, rec: Any) -> None:
        w = Window(sim, scenario.quality, size=(320, 240))
        while sim.now < at:
            w.frame(0.1)
        press(pygame.K_p)
        w.frame(0.0)
        while w.panel.row.key != key:
            press(pygame.K_DOWN)
            w.frame(0.0)
        for ch in value:
            press(pygame.K_PERIOD if ch == "." else ord(ch), ch)
        press(pygame.K_RETURN)
        w.frame(0.0)
        press(pygame.K_p)
        for _ in range(faster):
            press(pygame.K_RIGHTBRACKET)
        while not w.finished:
            w.frame(0.1)

    return drive
