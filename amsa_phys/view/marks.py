"""The marks every picture shares (``palette.MARKS``), drawn with pygame: a lost GPS fix, a
collision, the dashed distance line, and the darker tint text takes to read on white.

Kept apart from the renderer so that the window, the video, the replay and a test draw a
mark by one function: the plots draw the same marks with matplotlib's marker codes.
"""

from __future__ import annotations

import math

from ..palette import ADAPT_SWITCH, COLLISION, INK, LOST_FIX, OTHER_EVENT, PHASE
from .pg import pygame


def draw_lost_fix(surface: pygame.Surface, at: tuple[float, float], r: float = 4) -> None:
    """``palette.LOST_FIX``: a red × (the plots' ``x`` marker), ``r`` pixels each way."""
    px, py = at
    pygame.draw.line(surface, LOST_FIX.colour, (px - r, py - r), (px + r, py + r), 2)
    pygame.draw.line(surface, LOST_FIX.colour, (px - r, py + r), (px + r, py - r), 2)


def draw_collision(surface: pygame.Surface, at: tuple[float, float], r: float = 6) -> None:
    """``palette.COLLISION``: a red diamond with a dark edge (the plots' ``D`` marker)."""
    px, py = at
    pts = [(px, py - r), (px + r, py), (px, py + r), (px - r, py)]
    pygame.draw.polygon(surface, COLLISION.colour, pts)
    pygame.draw.polygon(surface, INK, pts, 1)


#: the order the slider's marks are drawn in: the many (lost fixes) under the few
SLIDER_ORDER = ("lost fix", "other", "collision", "change", "adapt", "phase")


def slider_kind(kind: str) -> str:
    """The mark an event of ``kind`` gets on the slider (one of :data:`SLIDER_ORDER`)."""
    return kind if kind in SLIDER_ORDER else "other"


def draw_slider_mark(surface: pygame.Surface, kind: str, x: int, bar: pygame.Rect) -> None:
    """An event's mark on the replay's time slider, in the palette's language.

    Grey is the timeline: a phase start is a line through the slider, a change inside a
    phase (a timeline entry with ``new_phase: false``, or a live change from the window) a
    tick down into its upper half, an ``adapt:`` switch a grey ▼ above it. Red is an alert:
    a collision is a red ◆, a lost GPS fix a red × (the window's and the plots' marks,
    smaller). Anything else a component recorded is a dark dot under the bar.
    """
    mid = bar.centery
    kind = slider_kind(kind)
    if kind == "phase":
        pygame.draw.line(surface, PHASE, (x, bar.top - 5), (x, bar.bottom + 4), 2)
    elif kind == "change":
        pygame.draw.line(surface, PHASE, (x, bar.top - 5), (x, mid), 2)
    elif kind == "adapt":
        top = bar.top - 9
        triangle = [(x - 4, top), (x + 4, top), (x, top + 7)]
        pygame.draw.polygon(surface, ADAPT_SWITCH.colour, triangle)
    elif kind == "collision":
        draw_collision(surface, (x, mid), 5)
    elif kind == "lost fix":
        draw_lost_fix(surface, (x, mid + 2), 3)
    else:
        pygame.draw.circle(surface, OTHER_EVENT.colour, (x, bar.bottom + 3), 2)


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
