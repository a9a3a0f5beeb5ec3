"""Headless video of a run: frames on the simulated clock, streamed to the encoder.

Frame *k* shows the world at simulated time ``k * speedup / fps`` (after every instant
at or before it has run), so video time equals simulated time (``--speedup 1``) whatever the wall
clock does — a paused window records nothing, a fast machine records the same video as a
slow one. A run of duration *D* gives ``ceil(D * fps / speedup)`` frames.
"""

from __future__ import annotations

import io
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

from ..atomic import write_atomic
from ..engine.face import SimView
from ..model.scenario import Quality
from .camera import Camera
from .draw import Renderer
from .encoder import VideoEncoder
from .pg import pygame
from .scene import Scene

DEFAULT_SIZE = (1280, 720)
DEFAULT_FPS = 30
#: Pixel layout we ask pygame for, and its name for ffmpeg: the bytes go over unconverted.
MASKS = (0xFF0000, 0x00FF00, 0x0000FF, 0)
PIX_FMT = "bgr0" if sys.byteorder == "little" else "0rgb"


@dataclass(frozen=True)
class RecordOptions:
    """What ``--record``, ``--fps``, ``--size`` and ``--speedup`` asked for."""

    path: Path
    size: tuple[int, int] = DEFAULT_SIZE
    fps: int = DEFAULT_FPS
    speedup: Fraction = Fraction(1)


def new_surface(size: tuple[int, int]) -> pygame.Surface:
    """An offscreen 32-bit surface whose bytes ffmpeg reads as :data:`PIX_FMT`."""
    return pygame.Surface(size, 0, 32, MASKS)


class Recorder:
    """Renders the simulation at each frame time and feeds the encoder."""

    def __init__(
        self,
        sim: SimView,
        options: RecordOptions,
        quality: Quality | None = None,
        planned: Sequence[Fraction] | None = None,
    ) -> None:
        self.sim = sim
        self.options = options
        self.period = Fraction(options.speedup) / options.fps  # simulated seconds per frame
        self.total = math.ceil(sim.duration / self.period)
        self.index = 0
        self.scene = Scene(sim, quality, planned)  # the HUD counts the file's phases
        self.camera = Camera(options.size)
        self.renderer = Renderer(options.size)
        self.surfaces = [new_surface(options.size) for _ in range(2)]
        self.encoder = VideoEncoder(options.path, options.size, options.fps, PIX_FMT)
        self._status = [f"x{float(options.speedup):g}  video {options.fps} fps"]
        self.scene.expect(0.0)

    def next_time(self) -> Fraction | None:
        """Simulated time of the next frame, or None when every frame is out."""
        return self.period * self.index if self.index < self.total else None

    def capture(self) -> None:
        """Draw the next frame from the simulation's current state and queue it."""
        k = self.index
        t = self.period * k
        if k >= 2:
            self.encoder.wait_written()  # this surface's previous frame has left
        surface = self.surfaces[k % 2]
        frame = self.scene.frame(t=float(t))
        self.camera.update([(r.x, r.y, r.name) for r in frame.rovers], float(self.period))
        self.renderer.draw_under_boxes(surface, frame, self.camera, self._status)
        self.encoder.submit(surface.get_view("0"))
        self.index += 1
        self.scene.expect(float(self.period * self.index))

    def close(self) -> Path:
        """Finish the video (playable up to the last frame captured)."""
        return self.encoder.close()


@dataclass(frozen=True)
class SnapshotOptions:
    """What ``--snapshot`` and ``--snapshot-at`` asked for (``at`` None: the end)."""

    path: Path
    size: tuple[int, int] = DEFAULT_SIZE
    at: Fraction | None = None


class Snapshot:
    """One still frame at simulated time ``at``, saved as PNG (the README's pictures).

    Its scene samples the history (trails, GPS fixes) at every logged instant before the
    picture, so the trails look as they do in the video at that instant.
    """

    def __init__(
        self,
        sim: SimView,
        options: SnapshotOptions,
        quality: Quality | None = None,
        planned: Sequence[Fraction] | None = None,
    ) -> None:
        self.sim = sim
        self.options = options
        self.at = min(options.at if options.at is not None else sim.duration, sim.duration)
        self.scene = Scene(sim, quality, planned)  # the HUD counts the file's phases
        self.scene.expect(float(self.at))
        self.written: Path | None = None

    def next_time(self) -> Fraction | None:
        """The picture's time (None once it is taken)."""
        return None if self.written is not None else self.at

    def capture(self) -> None:
        """Take the picture: its time has come."""
        self.write(self.at)

    def write(self, t: Fraction | None = None) -> Path:
        """Render now and save (atomically: a temporary name, then a rename)."""
        size = self.options.size
        frame = self.scene.frame(t=None if t is None else float(t))
        camera = Camera(size)
        camera.update([(r.x, r.y, r.name) for r in frame.rovers], 0.0)
        surface = new_surface(size)
        Renderer(size).draw_under_boxes(surface, frame, camera)
        path = self.options.path
        png = io.BytesIO()  # encoded in memory: a full disk cannot leave half a picture
        pygame.image.save(surface, png, "png")
        write_atomic(path, png.getvalue())
        self.written = path
        return path

    def close(self) -> Path:
        """The picture (taken now if the run ended before its time)."""
        return self.written or self.write()
