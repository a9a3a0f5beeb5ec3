"""The mouse on the map: the wheel zooms at the pointer, a left drag pans.

One owner for the live window and the replay player, so both move the camera alike; each
handles what it has beyond the map (the player's time slider) before asking here.
"""

from __future__ import annotations

from .camera import Camera
from .pg import pygame

#: a drag in progress: where the pointer was at the last event, or None
Drag = tuple[int, int] | None


def pan_zoom(event: pygame.event.Event, camera: Camera, drag: Drag) -> tuple[bool, Drag]:
    """``(handled, drag)``: whether ``event`` was the map's, and the drag after it."""
    if event.type == pygame.MOUSEWHEEL:
        camera.zoom(1.15**event.y, pygame.mouse.get_pos())
        return True, drag
    if event.type == pygame.MOUSEBUTTONDOWN and event.button == 1:
        return True, event.pos
    if event.type == pygame.MOUSEBUTTONUP and event.button == 1:
        return True, None
    if event.type == pygame.MOUSEMOTION and drag is not None:
        camera.pan(event.pos[0] - drag[0], event.pos[1] - drag[1])
        return True, event.pos
    return False, drag
