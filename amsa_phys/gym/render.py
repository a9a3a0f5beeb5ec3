"""``render_mode="rgb_array"``: frames from the project's own renderer (``view/draw.py``).

The same Scene, Camera and Renderer as the window and the video, so what an agent is shown
is what a person debugging it sees. pygame is imported only by an environment that renders.
"""

from __future__ import annotations

import numpy as np

from ..engine.face import SimView
from ..model.scenario import Quality
from ..templatemarks import StandIn, marked
from ..view.camera import Camera
from ..view.draw import Renderer
from ..view.pg import pygame
from ..view.scene import Scene
from ..view.video import new_surface


def replaced_components(sim: SimView) -> list[str]:
    """The components the agent stands in for: their parameters (a replaced controller's
    ``Kv=0.35``) act on nothing, so the HUD must not list them as if they did."""
    return [path for path, _, _ in marked(sim.world.leaves, StandIn)]


class FrameSource:
    """Samples a simulation's history at every agent step and draws it on request."""

    def __init__(self, sim: SimView, quality: Quality | None, size: tuple[int, int]) -> None:
        self.sim = sim
        self.scene = Scene(sim, quality, replaced=replaced_components(sim))
        self.camera = Camera(size)
        self.renderer = Renderer(size)
        self.surface = new_surface(size)
        self._last_t = 0.0
        self.frame = self.scene.frame()

    def sample(self) -> None:
        """Record trails and GPS fixes now (called after every agent step): drawing only
        when asked would leave the trails as chords between two renders."""
        self.frame = self.scene.frame()

    def draw(self, status: list[str]) -> np.ndarray:
        """The last sampled instant as an ``(height, width, 3)`` uint8 array."""
        frame = self.frame
        self.camera.update([(r.x, r.y, r.name) for r in frame.rovers], frame.t - self._last_t)
        self._last_t = frame.t
        self.renderer.draw_under_boxes(self.surface, frame, self.camera, status)
        return np.ascontiguousarray(pygame.surfarray.array3d(self.surface).transpose(1, 0, 2))
