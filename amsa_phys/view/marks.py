"""The marks every picture shares (``palette.MARKS``), drawn with pygame: a lost GPS fix, a
collision, the dashed distance line, and the darker tint text takes to read on white.

Kept apart from the renderer so that the window, the video, the replay and a test draw a
mark by one function: the plots draw the same marks with matplotlib's marker codes.
"""

from __future__ import annotations

import math

from ..palette import COLLISION, INK, LOST_FIX
from .pg import pygame


def draw_lost_fix(surface: pygame.Surface, at: tuple[float, float]) -> None:
    """``palette.LOST_FIX``: a red × (the plots' ``x`` marker)."""
    px, py = at
    pygame.draw.line(surface, LOST_FIX.colour, (px - 4, py - 4), (px + 4, py + 4), 2)
    pygame.draw.line(surface, LOST_FIX.colour, (px - 4, py + 4), (px + 4, py - 4), 2)


def draw_collision(surface: pygame.Surface, at: tuple[float, float]) -> None:
    """``palette.COLLISION``: a red diamond with a dark edge (the plots' ``D`` marker)."""
    px, py = at
    pts = [(px, py - 6), (px + 6, py), (px, py + 6), (px - 6, py)]
    pygame.draw.polygon(surface, COLLISION.colour, pts)
    pygame.draw.polygon(surface, INK, pts, 1)


def dashed(
    surface: pygame.Surface,
    colour: tuple[int, int, int],
    a: tuple[float, float],
    b: tuple[float, float],
    dash: float = 8.0,
) -> None:
    """A 2 px line from ``a`` to ``b`` drawn as dashes with equal gaps."""
    length = math.hypot(b[0] - a[0], b[1] - a[1])
    if length < 1:
        return
    n = int(length // (2 * dash)) + 1
    ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
    for k in range(n):
        s0, s1 = 2 * k * dash, min(length, (2 * k + 1) * dash)
        pygame.draw.line(
            surface, colour, (a[0] + ux * s0, a[1] + uy * s0), (a[0] + ux * s1, a[1] + uy * s1), 2
        )


def darker(colour: tuple[int, int, int]) -> tuple[int, int, int]:
    """``colour`` at 70 %: text in it stays readable on a white box (amber is not)."""
    return tuple(int(c * 0.7) for c in colour)  # type: ignore[return-value]
