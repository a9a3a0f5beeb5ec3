"""``render_mode="human"``: the episode drawn in a window, at the agent's own rate.

The same Scene, Camera and Renderer as ``rgb_array`` (``gym/render.py``) and as the
interactive window, drawn straight onto the display surface after every step, then paced to
``metadata["render_fps"]`` as Gymnasium's own environments do (a person watches the episode
in simulated real time). The window's events are pumped so the OS does not think it hung;
closing it ends nothing but the drawing (the agent's loop owns the episode).
"""

from __future__ import annotations

from ..engine.face import SimView
from ..model.scenario import Quality
from ..view.pg import pygame
from ..view.window import open_display
from .render import FrameSource


class HumanView(FrameSource):
    """A FrameSource that also shows each frame in a window."""

    def __init__(
        self, sim: SimView, quality: Quality | None, size: tuple[int, int], fps: float
    ) -> None:
        super().__init__(sim, quality, size)
        open_display()  # RuntimeError (no display) is reported by the env as it is
        pygame.font.init()
        self.screen = pygame.display.set_mode(size)
        pygame.display.set_caption("amsa-phys: amsa_phys/Follow-v0")
        self.clock = pygame.time.Clock()
        self.fps = fps
        self.closed = False

    def show(self, status: list[str]) -> None:
        """Draw the last sampled instant in the window and wait for the frame's time."""
        if self.closed:
            return
        for event in pygame.event.get():
            if event.type == pygame.QUIT:
                self.close()
                return
        frame = self.frame
        self.camera.update([(r.x, r.y, r.name) for r in frame.rovers], frame.t - self._last_t)
        self._last_t = frame.t
        self.renderer.draw(self.screen, frame, self.camera, status)
        pygame.display.flip()
        self.clock.tick(self.fps)

    def close(self) -> None:
        """Close the window (safe to call twice)."""
        if not self.closed:
            self.closed = True
            pygame.display.quit()
