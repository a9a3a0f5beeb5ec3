"""The one place that imports pygame, quietly and without SDL's signal handlers.

``pygame.init()`` / ``display.init()`` install SDL handlers that turn SIGINT and SIGTERM into
a queued QUIT event: a headless recording would then ignore Ctrl-C, ``kill`` and a CI
timeout (measurements.md). ``SDL_NO_SIGNAL_HANDLERS=1`` keeps Python's own handlers, so an
interrupt reaches our code as KeyboardInterrupt and the video is finalised. Offscreen
rendering only ever needs ``pygame.font.init()``.
"""

from __future__ import annotations

import os
from importlib import resources
from typing import Any

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
os.environ.setdefault("SDL_NO_SIGNAL_HANDLERS", "1")

import pygame

FONT_FILE = "DejaVuSansMono.ttf"

_fonts: dict[int, Any] = {}


def font(size: int) -> pygame.font.Font:
    """The bundled monospace font (DejaVu Sans Mono) at ``size`` px, cached.

    Bundled rather than a system font so that frames look the same on every machine (and a
    golden frame can be compared).
    """
    if size not in _fonts:
        if not pygame.font.get_init():
            pygame.font.init()
        path = resources.files("amsa_phys") / "assets" / "fonts" / FONT_FILE
        with resources.as_file(path) as real:
            _fonts[size] = pygame.font.Font(str(real), size)
    return _fonts[size]


__all__ = ["font", "pygame"]
